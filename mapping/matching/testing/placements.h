#pragma once
// Submap origins for the landmark association tests: level poses and placements with isotropic
// marginal covariances.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/math/so3.h"
#include "mapping/matching/submap_placement.h"

namespace cairn::testing {

inline Eigen::Isometry3d YawedPose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(Eigen::Vector3d(0.0, 0.0, yaw));
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

// T with standard deviation sigma_t (m) on each translation and sigma_r (rad) on each rotation.
inline SubmapPlacement PlacedWithSigma(const Eigen::Isometry3d& T, double sigma_t, double sigma_r) {
  SubmapPlacement p;
  p.T_world_submap = T;
  Eigen::Matrix<double, 6, 1> d;
  d << sigma_t, sigma_t, sigma_t, sigma_r, sigma_r, sigma_r;
  p.covariance = d.cwiseAbs2().asDiagonal();
  return p;
}

}  // namespace cairn::testing
