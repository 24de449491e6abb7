#include "sim/tag_view_renderer.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "sim/tag36h11_code.h"

namespace cairn::sim {

TagViewRenderer::TagViewRenderer(const Terrain& terrain, const PinholeRadTan& camera, RenderOptions options)
    : terrain_(terrain), camera_(camera), options_(options) {
  // 30 m above the world's middle, pitched 60 deg down: the ground in view is 35-45 m away.
  const double pitch = 60.0 * std::numbers::pi / 180.0;
  Eigen::Matrix3d R_level;  // camera z along world x, image down along world -z
  R_level << 0, 0, 1, -1, 0, 0, 0, -1, 0;
  T_world_cam_.setIdentity();
  T_world_cam_.linear() = R_level * Eigen::AngleAxisd(-pitch, Eigen::Vector3d::UnitX()).toRotationMatrix();
  T_world_cam_.translation() = Eigen::Vector3d(0.0, 0.0, terrain.Height(0.0, 0.0) + 30.0);
}

Expected<TagView> TagViewRenderer::Render(int id, double tag_size, const Eigen::Isometry3d& T_cam_tag,
                                          uint64_t noise_seed, int margin) const {
  const auto bits = Tag36h11MarkerBits(id);
  if (!bits.ok()) return bits.status();
  if (!(tag_size > 0.0)) return InvalidArgumentError("tag view: the tag size must be > 0");
  TagView view;
  // Corners of the black square, and of the white ring (10 of the square's 8 modules) for the window.
  const double h = 0.5 * tag_size;
  const std::array<Eigen::Vector2d, 4> square = {Eigen::Vector2d(-h, h), Eigen::Vector2d(h, h), Eigen::Vector2d(h, -h),
                                                 Eigen::Vector2d(-h, -h)};
  double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
  for (int k = 0; k < 4; ++k) {
    for (const double ring : {1.0, 1.25}) {
      const Eigen::Vector3d p = T_cam_tag * Eigen::Vector3d(ring * square[k].x(), ring * square[k].y(), 0.0);
      if (!(p.z() > 0.05)) return OutOfRangeError("tag view: the tag is not in front of the camera");
      const double u = camera_.fx * p.x() / p.z() + camera_.cx, v = camera_.fy * p.y() / p.z() + camera_.cy;
      if (ring == 1.0) view.corners[k] = Eigen::Vector2d(u, v);
      u_lo = std::min(u_lo, u);
      u_hi = std::max(u_hi, u);
      v_lo = std::min(v_lo, v);
      v_hi = std::max(v_hi, v);
    }
  }
  const int x0 = static_cast<int>(std::floor(u_lo)) - margin, y0 = static_cast<int>(std::floor(v_lo)) - margin;
  const int x1 = static_cast<int>(std::ceil(u_hi)) + margin, y1 = static_cast<int>(std::ceil(v_hi)) + margin;
  if (x0 < 0 || y0 < 0 || x1 >= camera_.width || y1 >= camera_.height)
    return OutOfRangeError("tag view: the tag and its margin are not wholly inside the image");
  view.x0 = x0 & ~1;
  view.y0 = y0 & ~1;
  view.width = x1 - view.x0 + 1;
  view.height = y1 - view.y0 + 1;

  PinholeRadTan window = camera_;
  window.width = view.width;
  window.height = view.height;
  window.cx = camera_.cx - view.x0;
  window.cy = camera_.cy - view.y0;
  window.k1 = window.k2 = window.p1 = window.p2 = 0.0;

  RenderScene scene;
  scene.terrain = &terrain_;
  SimMarker m;
  m.id = id;
  m.size = tag_size;
  m.bits = *bits;
  // The marker's face frame (z out of the face) is a half turn about x from AprilTag's.
  const Eigen::Isometry3d T_cam_face = T_cam_tag * Eigen::AngleAxisd(std::numbers::pi, Eigen::Vector3d::UnitX());
  m.T_body_marker = T_world_cam_ * T_cam_face;
  scene.markers.push_back(m);
  // The sun behind the camera: the tag is lit as the cosine of its viewing angle.
  scene.sun_direction = (T_world_cam_.translation() - m.T_body_marker.translation()).normalized();
  CameraRenderer::Render(scene, window, T_world_cam_, options_, noise_seed, &view.pixels, nullptr);
  return view;
}

}  // namespace cairn::sim
