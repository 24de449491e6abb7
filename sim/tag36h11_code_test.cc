#include "sim/tag36h11_code.h"

#include <set>
#include <vector>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>
#include <gtest/gtest.h>

#include "sim/camera_renderer.h"

namespace cairn::sim {
namespace {

TEST(Tag36h11CodeTest, EveryIdHasItsOwnCodeAndBadIdsAreRejected) {
  ASSERT_EQ(Tag36h11Count(), 587);
  std::set<uint64_t> seen;
  for (int id = 0; id < Tag36h11Count(); ++id) {
    auto bits = Tag36h11MarkerBits(id);
    ASSERT_TRUE(bits.ok()) << id;
    EXPECT_EQ(*bits >> 36, 0u) << id;
    EXPECT_TRUE(seen.insert(*bits).second) << id;
  }
  EXPECT_FALSE(Tag36h11MarkerBits(-1).ok());
  auto bad = Tag36h11MarkerBits(587);
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.status().message().find("587"), std::string::npos);
}

// Renders markers seen obliquely by a camera and decodes them with the apriltag library's own
// detector: the simulator's markers are real tag36h11 tags, so detection of teammates can be
// tested on simulated images.
TEST(Tag36h11CodeTest, RenderedMarkersDecodeWithTheAprilTagDetector) {
  WorldOptions w;
  w.size = 24.0;
  w.seed = 4;
  w.lander.clear();
  const Terrain terrain = Terrain::Generate(w);
  PinholeRadTan k;
  k.width = 320;
  k.height = 240;
  k.fx = k.fy = 300.0;
  k.cx = 159.5;
  k.cy = 119.5;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // looking along +x, image up = +z
  T_world_cam.translation() = Eigen::Vector3d(0, 0, terrain.Height(0, 0) + 2.0);

  apriltag_family_t* family = tag36h11_create();
  apriltag_detector_t* detector = apriltag_detector_create();
  apriltag_detector_add_family(detector, family);
  detector->nthreads = 1;
  for (const int id : {0, 7, 21, 200, 586}) {
    RenderScene scene;
    scene.terrain = &terrain;
    scene.sun_direction = Eigen::Vector3d(-1, 0.3, 1).normalized();
    SimMarker m;
    m.id = id;
    m.size = 0.3;
    m.bits = *Tag36h11MarkerBits(id);
    // Facing the camera (marker x = world -y, y = world z), then turned 30 deg about the vertical
    // and 15 deg about its own x so the view is oblique.
    Eigen::Matrix3d R_face;
    R_face << 0, 0, -1, -1, 0, 0, 0, 1, 0;
    m.T_body_marker.linear() = Eigen::AngleAxisd(0.52, Eigen::Vector3d::UnitZ()).toRotationMatrix() * R_face *
                               Eigen::AngleAxisd(0.26, Eigen::Vector3d::UnitX()).toRotationMatrix();
    m.T_body_marker.translation() = T_world_cam.translation() + Eigen::Vector3d(1.5, 0.1, 0.05);
    scene.markers.push_back(m);
    std::vector<uint8_t> img;
    CameraRenderer::Render(scene, k, T_world_cam, RenderOptions{}, 3, &img, nullptr);

    image_u8_t view{k.width, k.height, k.width, img.data()};
    zarray_t* detections = apriltag_detector_detect(detector, &view);
    std::vector<int> ids;
    for (int i = 0; i < zarray_size(detections); ++i) {
      apriltag_detection_t* d = nullptr;
      zarray_get(detections, i, &d);
      ids.push_back(d->id);
      EXPECT_EQ(d->hamming, 0) << "id " << id;
    }
    apriltag_detections_destroy(detections);
    EXPECT_EQ(ids, std::vector<int>{id});
  }
  apriltag_detector_destroy(detector);
  tag36h11_destroy(family);
}

}  // namespace
}  // namespace cairn::sim
