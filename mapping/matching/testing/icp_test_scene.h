#pragma once
// A synthetic terrain for the ICP tests (four_dof_icp_test.cc, six_dof_icp_test.cc) and clouds
// sampled from it.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <random>
#include <vector>

#include <Eigen/Core>

#include "estimation/math/ordered_draws.h"

namespace cairn {

// Samples the parallelogram o + a u + b v at cell centres shifted by `offset` (in cells) so that
// two clouds of one scene can hold different points.
inline void SampleRect(const Eigen::Vector3d& o, const Eigen::Vector3d& u, const Eigen::Vector3d& v, double spacing,
                double offset, std::vector<Eigen::Vector3d>* out) {
  const int nu = std::max(1, static_cast<int>(std::lround(u.norm() / spacing)));
  const int nv = std::max(1, static_cast<int>(std::lround(v.norm() / spacing)));
  for (int i = 0; i < nu; ++i) {
    for (int j = 0; j < nv; ++j) out->push_back(o + (i + offset) / nu * u + (j + offset) / nv * v);
  }
}

// Sides and top of a box standing on z = 0.
inline void SampleBox(double cx, double cy, double sx, double sy, double h, double yaw, double spacing,
               double offset, std::vector<Eigen::Vector3d>* out) {
  const Eigen::Vector3d ex(std::cos(yaw), std::sin(yaw), 0.0), ey(-std::sin(yaw), std::cos(yaw), 0.0);
  const Eigen::Vector3d up(0.0, 0.0, h);
  const Eigen::Vector3d o = Eigen::Vector3d(cx, cy, 0.0) - 0.5 * sx * ex - 0.5 * sy * ey;
  SampleRect(o + up, sx * ex, sy * ey, spacing, offset, out);
  SampleRect(o, sx * ex, up, spacing, offset, out);
  SampleRect(o, sy * ey, up, spacing, offset, out);
  SampleRect(o + sy * ey, sx * ex, up, spacing, offset, out);
  SampleRect(o + sx * ex, sy * ey, up, spacing, offset, out);
}

// A gravity-aligned terrain in A's frame: ground, a slope, boxes at several headings and a ridge
// of two tilted faces (a crude rock), so every one of x, y, z and yaw is constrained.
inline std::vector<Eigen::Vector3d> IcpTestScene(double spacing, double offset) {
  std::vector<Eigen::Vector3d> pts;
  SampleRect({-3.0, -3.0, 0.0}, {6.0, 0.0, 0.0}, {0.0, 4.5, 0.0}, spacing, offset, &pts);
  SampleRect({-3.0, 1.5, 0.0}, {6.0, 0.0, 0.0}, {0.0, 1.5, 0.6}, spacing, offset, &pts);  // 22 deg slope
  SampleBox(-1.2, -1.0, 0.8, 0.5, 0.5, 0.3, spacing, offset, &pts);
  SampleBox(0.8, -1.8, 0.6, 0.6, 0.8, -0.5, spacing, offset, &pts);
  SampleBox(0.5, 0.6, 1.0, 0.4, 0.4, 1.2, spacing, offset, &pts);
  SampleBox(1.5, -0.2, 0.5, 0.7, 0.6, 0.0, spacing, offset, &pts);
  SampleRect({-2.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 0.45, 0.45}, spacing, offset, &pts);
  SampleRect({-2.0, 0.9, 0.0}, {1.0, 0.0, 0.0}, {0.0, -0.45, 0.45}, spacing, offset, &pts);
  return pts;
}

// Points of `scene` with x in [x_min, x_max], moved by T and given noise.
template <class Transform>
std::vector<Eigen::Vector3d> IcpTestCloud(const std::vector<Eigen::Vector3d>& scene, double x_min, double x_max,
                                          const Transform& T, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> gauss(0.0, 1.0);
  std::vector<Eigen::Vector3d> out;
  for (const Eigen::Vector3d& p : scene) {
    if (p.x() < x_min || p.x() > x_max) continue;
    out.push_back(Eigen::Vector3d(T * p) + noise * DrawVector3(gauss, rng));
  }
  return out;
}

}  // namespace cairn
