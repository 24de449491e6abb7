#include "sim/camera_renderer.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cairn::sim {
namespace {

WorldOptions RenderWorld() {
  WorldOptions w;
  w.size = 24.0;
  w.seed = 4;
  w.lander.clear();
  return w;
}

PinholeRadTan SmallCamera() {
  PinholeRadTan k;
  k.width = 96;
  k.height = 48;
  k.fx = k.fy = 100.0;
  k.cx = 47.5;
  k.cy = 23.5;
  return k;
}

Eigen::Isometry3d LookingForwardDown(const Terrain& t, double x, double y, double height) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  Eigen::Matrix3d R;
  R.col(0) = -Eigen::Vector3d::UnitY();
  R.col(1) = -Eigen::Vector3d::UnitZ();
  R.col(2) = Eigen::Vector3d::UnitX();
  T.linear() = R * Eigen::AngleAxisd(-0.35, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, t.Height(x, y) + height);
  return T;
}

// Every rendered depth, back-projected, lies on the terrain, and the ray to it stays above the
// terrain: the image's depth is the ray-cast ground truth.
TEST(CameraRendererTest, RenderedDepthIsTheTerrainGroundTruth) {
  const Terrain terrain = Terrain::Generate(RenderWorld());
  RenderScene scene;
  scene.terrain = &terrain;
  const PinholeRadTan k = SmallCamera();
  const Eigen::Isometry3d T = LookingForwardDown(terrain, -6, 0.5, 1.3);
  std::vector<uint8_t> img;
  std::vector<float> depth;
  CameraRenderer::Render(scene, k, T, RenderOptions{}, 1, &img, &depth);
  int valid = 0;
  for (int v = 0; v < k.height; ++v) {
    for (int u = 0; u < k.width; ++u) {
      const float z = depth[static_cast<size_t>(v * k.width + u)];
      if (z <= 0.0f) continue;
      ++valid;
      const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
      const Eigen::Vector3d p = T * (ray * static_cast<double>(z));
      ASSERT_NEAR(p.z(), terrain.Height(p.x(), p.y()), 2e-4) << u << "," << v;
      for (double s = 0.02; s < 0.995; s += 0.01) {
        const Eigen::Vector3d q = T * (ray * (s * z));
        ASSERT_GT(q.z(), terrain.Height(q.x(), q.y()) - 1e-6) << u << "," << v << " occluded at " << s;
      }
    }
  }
  EXPECT_GT(valid, k.width * k.height / 2);
}

// Full-size cameras, a forward-looking one (the rover's: the search starts from the hit of the
// pixel below) and a steep wide-angle one with roll (the hexacopter's: from pixels further down
// the image of the vertical, or from the tile bounds): every rendered depth is that of the plain
// ray cast from the camera, and the pixels without depth are the ones whose ray misses.
TEST(CameraRendererTest, FullSizeCamerasShowTheFirstHitOfEveryRay) {
  const Terrain terrain = Terrain::Generate(RenderWorld());
  RenderScene scene;
  scene.terrain = &terrain;
  struct View {
    int width, height;
    double f, tilt, roll, height_above_ground;
  };
  for (const View& view : {View{1024, 508, 1080.0, 0.44, 0.03, 1.3}, View{666, 506, 350.0, 1.05, 0.2, 4.5}}) {
    PinholeRadTan k;
    k.width = view.width;
    k.height = view.height;
    k.fx = k.fy = view.f;
    k.cx = (k.width - 1) / 2.0;
    k.cy = (k.height - 1) / 2.0;
    Eigen::Isometry3d T = LookingForwardDown(terrain, -7, 1.5, view.height_above_ground);
    T.linear() = T.linear() * Eigen::AngleAxisd(0.35 - view.tilt, Eigen::Vector3d::UnitX()).toRotationMatrix() *
                 Eigen::AngleAxisd(view.roll, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    std::vector<uint8_t> img;
    std::vector<float> depth;
    CameraRenderer::Render(scene, k, T, RenderOptions{}, 1, &img, &depth);
    int checked = 0, sky = 0;
    for (int v = 0; v < k.height; v += 3) {
      for (int u = v % 7; u < k.width; u += 7) {
        const Eigen::Vector3d ray((u - k.cx) / k.fx, (v - k.cy) / k.fy, 1.0);
        const Eigen::Vector3d dir = T.linear() * ray.normalized();
        const TerrainHit hit = terrain.Raycast(T.translation(), dir, RenderOptions{}.max_range);
        const float z = depth[static_cast<size_t>(v * k.width + u)];
        if (hit.t < 0) {
          ASSERT_EQ(z, 0.0f) << u << "," << v;
          ++sky;
          continue;
        }
        const double expected = hit.t * ray.normalized().z();
        ASSERT_NEAR(z, expected, 1e-6 * expected + 1e-6) << u << "," << v;
        ++checked;
      }
    }
    EXPECT_GT(checked, k.width * k.height / 30);
    (void)sky;
  }
}

TEST(CameraRendererTest, SameSeedSameImageAndNoiseDependsOnSeed) {
  const Terrain terrain = Terrain::Generate(RenderWorld());
  RenderScene scene;
  scene.terrain = &terrain;
  const Eigen::Isometry3d T = LookingForwardDown(terrain, 0, 0, 1.3);
  std::vector<uint8_t> a, b, c;
  CameraRenderer::Render(scene, SmallCamera(), T, RenderOptions{}, 5, &a, nullptr);
  CameraRenderer::Render(scene, SmallCamera(), T, RenderOptions{}, 5, &b, nullptr);
  CameraRenderer::Render(scene, SmallCamera(), T, RenderOptions{}, 6, &c, nullptr);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // Texture everywhere on the ground: neighbouring pixels differ beyond noise in most places.
  int textured = 0;
  for (size_t i = 1; i < a.size(); ++i) textured += std::abs(a[i] - a[i - 1]) > 1;
  EXPECT_GT(textured, static_cast<int>(a.size()) / 3);
}

// A marker facing the camera shows its black border and its data bits.
TEST(CameraRendererTest, MarkerFacingTheCameraShowsItsBits) {
  const Terrain terrain = Terrain::Generate(RenderWorld());
  RenderScene scene;
  scene.terrain = &terrain;
  scene.sun_direction = Eigen::Vector3d(-1, 0, 1).normalized();
  PinholeRadTan k;
  k.width = k.height = 100;
  k.fx = k.fy = 400.0;
  k.cx = k.cy = 49.5;
  Eigen::Isometry3d T_world_cam = Eigen::Isometry3d::Identity();
  T_world_cam.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;  // looking along +x, image up = +z
  T_world_cam.translation() = Eigen::Vector3d(0, 0, terrain.Height(0, 0) + 2.0);
  SimMarker m;
  m.size = 0.2;
  m.bits = 0xF0F0F0F0Full;
  // Marker at 1 m facing -x (towards the camera); marker x = world -y, marker y = world z.
  m.T_body_marker.linear() << 0, 0, -1, -1, 0, 0, 0, 1, 0;
  m.T_body_marker.translation() = T_world_cam.translation() + Eigen::Vector3d(1.0, 0, 0);
  scene.markers.push_back(m);
  RenderOptions o;
  o.read_noise = 0.0;
  o.shot_noise = 0.0;
  o.exposure = 0.4;  // white stays below saturation
  o.ambient = 0.2;
  std::vector<uint8_t> img;
  CameraRenderer::Render(scene, k, T_world_cam, o, 1, &img, nullptr);
  // A module is 0.025 m = 10 px; the marker's top-left data bit is module (2, 2).
  auto at_module = [&](int r, int c) {
    const int u = static_cast<int>(k.cx + (c - 5 + 0.5) * 10), v = static_cast<int>(k.cy + (r - 5 + 0.5) * 10);
    return img[static_cast<size_t>(v * k.width + u)];
  };
  EXPECT_GT(at_module(0, 0), 100);  // quiet ring
  EXPECT_LT(at_module(1, 4), 20);   // border
  for (int bit = 0; bit < 36; ++bit) {
    const bool white = (m.bits >> (35 - bit)) & 1;
    const uint8_t value = at_module(2 + bit / 6, 2 + bit % 6);
    EXPECT_EQ(value > 60, white) << "bit " << bit << " value " << int(value);
  }
}

// A camera of `width` x `height` px, focal length `f`, principal point (cx, cy), 2 m above the
// terrain at the origin, looking level along +x.
PinholeRadTan Pinhole(int width, int height, double f, double cx, double cy) {
  PinholeRadTan k;
  k.width = width;
  k.height = height;
  k.fx = k.fy = f;
  k.cx = cx;
  k.cy = cy;
  return k;
}

Eigen::Isometry3d LevelAlongX(const Terrain& terrain) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T.translation() = Eigen::Vector3d(0, 0, terrain.Height(0, 0) + 2.0);
  return T;
}

// A pixel averages the light over its area: one that a marker's white-to-black edge cuts at a
// quarter of its width is three quarters white (one ray per pixel would make it all white, and
// every edge would snap to pixel boundaries).
TEST(CameraRendererTest, AMarkerEdgeThroughAPixelGivesItTheCoveredShare) {
  const Terrain terrain = Terrain::Generate(RenderWorld());
  const PinholeRadTan k = Pinhole(320, 240, 200.0, 159.5, 119.5);
  const Eigen::Isometry3d T_world_cam = LevelAlongX(terrain);
  // Face on at 2 m: marker x runs along image u at 100 px/m. The quiet ring ends and the black
  // border starts at x = -4 modules; put that at u = 100.25.
  const double module = (159.5 - 100.25) / 100.0 / 4.0;
  SimMarker m;
  m.id = 0;
  m.size = 8.0 * module;
  Eigen::Matrix3d R_face;
  R_face << 0, 0, -1, -1, 0, 0, 0, 1, 0;
  m.T_body_marker.linear() = R_face;
  m.T_body_marker.translation() = T_world_cam.translation() + Eigen::Vector3d(2.0, 0.0, 0.0);
  RenderScene scene;
  scene.terrain = &terrain;
  scene.sun_direction = Eigen::Vector3d(-1, 0, 0.2).normalized();
  scene.markers.push_back(m);
  RenderOptions o;
  o.read_noise = 0.0;
  o.shot_noise = 0.0;
  o.exposure = 0.4;  // white stays below saturation
  std::vector<uint8_t> img;
  CameraRenderer::Render(scene, k, T_world_cam, o, 1, &img, nullptr);
  const auto at = [&](int u) { return static_cast<double>(img[static_cast<size_t>(119 * k.width + u)]); };
  const double white = at(98), black = at(102);
  ASSERT_GT(white, 100.0);
  // Albedo 0.85 white, 0.04 black: three quarters white is 0.6475.
  EXPECT_NEAR((at(100) - black) / (white - black), 0.75, 0.04) << at(99) << " " << at(100) << " " << at(101);
  EXPECT_NEAR(at(99), white, 1.0);
  EXPECT_NEAR(at(101), black, 1.0);
}

// A marker seen at a grazing angle (lying flat 4 mm below the camera, 2 m ahead, where row 60's
// centre ray meets it): some of that pixel's rays point above the horizon and never meet its
// plane. They must not be followed to infinity (an integer overflow under UBSan).
TEST(CameraRendererTest, AMarkerSeenAtAGrazingAngleRendersWithoutOverflow) {
  const Terrain terrain = Terrain::Generate(RenderWorld());
  // Row 60's centre 0.2 px below the horizon, its top rays above.
  const PinholeRadTan k = Pinhole(160, 120, 100.0, 79.5, 59.8);
  const Eigen::Isometry3d T_world_cam = LevelAlongX(terrain);
  SimMarker m;
  m.id = 0;
  m.size = 0.5;
  m.T_body_marker.translation() = T_world_cam.translation() + Eigen::Vector3d(2.0, 0.0, -0.004);  // face up
  RenderScene scene;
  scene.terrain = &terrain;
  scene.markers.push_back(m);
  std::vector<uint8_t> img;
  CameraRenderer::Render(scene, k, T_world_cam, RenderOptions{}, 1, &img, nullptr);
  ASSERT_EQ(img.size(), static_cast<size_t>(k.width * k.height));
}

}  // namespace
}  // namespace cairn::sim
