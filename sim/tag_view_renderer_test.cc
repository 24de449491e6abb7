#include "sim/tag_view_renderer.h"

#include <gtest/gtest.h>

#include "detection/tag_detector.h"
#include "detection/tag_pose_estimator.h"

namespace cairn::sim {
namespace {

WorldOptions TagWorld() {
  WorldOptions w;
  w.size = 20.0;
  w.resolution = 0.2;
  return w;
}

PinholeRadTan RoverLike() {
  PinholeRadTan k;
  k.width = 1024;
  k.height = 508;
  k.fx = k.fy = 1080.0;
  k.cx = 511.5;
  k.cy = 253.5;
  return k;
}

TEST(TagViewRendererTest, TheDetectorFindsTheTagWhereItWasDrawn) {
  const Terrain terrain = Terrain::Generate(TagWorld());
  const PinholeRadTan k = RoverLike();
  const TagViewRenderer renderer(terrain, k);
  Eigen::Isometry3d T_cam_tag = Eigen::Isometry3d::Identity();
  T_cam_tag.linear() = Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitY()).toRotationMatrix() *
                       Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  T_cam_tag.translation() = Eigen::Vector3d(0.3, -0.1, 3.0);
  const auto view = renderer.Render(7, 0.16, T_cam_tag, 1);
  ASSERT_TRUE(view.ok()) << view.status().ToString();
  EXPECT_EQ(view->x0 % 2, 0);
  EXPECT_EQ(view->pixels.size(), static_cast<size_t>(view->width * view->height));
  TagDetector detector;
  const auto found = detector.Detect(Image::GrayView(view->pixels.data(), view->width, view->height, view->width));
  ASSERT_TRUE(found.ok());
  ASSERT_EQ(found->size(), 1u);
  EXPECT_EQ((*found)[0].id, 7);
  std::array<Eigen::Vector2d, 4> corners = (*found)[0].corners;
  for (int c = 0; c < 4; ++c) {
    corners[c] += Eigen::Vector2d(view->x0, view->y0);
    EXPECT_LT((corners[c] - view->corners[c]).norm(), 1.0) << "corner " << c;
  }
  TagPoseOptions po;
  po.tag_size = 0.16;
  po.sample_corners = false;
  const auto pose = TagPoseEstimator(po).Estimate(corners, k);
  ASSERT_TRUE(pose.ok());
  EXPECT_LT((pose->T_cam_tag.translation() - T_cam_tag.translation()).norm(), 0.03);
}

TEST(TagViewRendererTest, RefusesTagsOutsideTheImageOrBehindTheCamera) {
  const Terrain terrain = Terrain::Generate(TagWorld());
  const TagViewRenderer renderer(terrain, RoverLike());
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(0.0, 0.0, -2.0);
  EXPECT_EQ(renderer.Render(0, 0.16, T, 1).status().code(), StatusCode::kOutOfRange);
  T.translation() = Eigen::Vector3d(2.0, 0.0, 2.0);  // off the image's side
  EXPECT_EQ(renderer.Render(0, 0.16, T, 1).status().code(), StatusCode::kOutOfRange);
  T.translation() = Eigen::Vector3d(0.0, 0.0, 2.0);
  EXPECT_FALSE(renderer.Render(587, 0.16, T, 1).ok());  // not a tag36h11 id
  EXPECT_FALSE(renderer.Render(0, 0.0, T, 1).ok());
}

}  // namespace
}  // namespace cairn::sim
