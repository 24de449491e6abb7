#pragma once
// Planar faces of a made-up world as submaps see them, for the plane association and matching
// tests.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "mapping/submap_plane.h"

namespace cairn::testing {

// The rectangle of the world plane through `c_w` with normal `n_w` (half extents along
// SubmapPlane's axes), as the submap at T_w_s sees it, with standard deviation `sigma` on each of
// (a, b, d).
inline SubmapPlane FaceSeenFrom(const Eigen::Isometry3d& T_w_s, const Eigen::Vector3d& n_w,
                                const Eigen::Vector3d& c_w, const Eigen::Vector2d& half = {1.5, 1.5},
                                double sigma = 0.005, uint32_t points = 1000) {
  SubmapPlane p;
  const Eigen::Vector3d n = T_w_s.linear().transpose() * n_w.normalized();
  const Eigen::Vector3d c = T_w_s.inverse() * c_w;
  p.normal = n.cast<float>();
  p.offset = static_cast<float>(-n.dot(c));
  p.centroid = c.cast<float>();
  p.covariance = Eigen::Matrix3f::Identity() * static_cast<float>(sigma * sigma);
  p.max = half.cast<float>();
  p.min = -p.max;
  p.area = static_cast<float>(4.0 * half.x() * half.y());
  p.points = points;
  return p;
}

}  // namespace cairn::testing
