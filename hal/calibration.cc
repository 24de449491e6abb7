#include "hal/calibration.h"

namespace cairn {

Eigen::Vector2d PinholeRadTan::Distort(const Eigen::Vector2d& u) const {
  const double x = u.x(), y = u.y();
  const double r2 = x * x + y * y;
  const double radial = 1.0 + k1 * r2 + k2 * r2 * r2;
  return {x * radial + 2.0 * p1 * x * y + p2 * (r2 + 2.0 * x * x),
          y * radial + p1 * (r2 + 2.0 * y * y) + 2.0 * p2 * x * y};
}

Eigen::Vector2d PinholeRadTan::Undistort(const Eigen::Vector2d& d) const {
  Eigen::Vector2d u = d;
  for (int i = 0; i < 20; ++i) {
    const Eigen::Vector2d err = Distort(u) - d;
    u -= err;
    if (err.squaredNorm() < 1e-24) break;
  }
  return u;
}

Eigen::Vector2d PinholeRadTan::Project(const Eigen::Vector3d& p_cam) const {
  const Eigen::Vector2d d = Distort(p_cam.head<2>() / p_cam.z());
  return {fx * d.x() + cx, fy * d.y() + cy};
}

}  // namespace cairn
