#pragma once
// Straight edges of a made-up world as submaps see them, for the line association and landmark
// tests.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/math/tangent_axes.h"
#include "mapping/submap_line.h"

namespace cairn::testing {

// The world segment a-b as the submap at T_w_s measures it, anchored 1 m above the submap's
// origin, with the error `e` (direction along u, w; offset along u, w of the middle) applied and
// the covariance of (n, v) that gives e the sigmas (sigma_r, sigma_r, sigma_t, sigma_t).
inline SubmapLine EdgeSeenFrom(const Eigen::Isometry3d& T_w_s, const Eigen::Vector3d& a_w,
                               const Eigen::Vector3d& b_w, double sigma_r = 0.005, double sigma_t = 0.01,
                               const Eigen::Vector4d& e = Eigen::Vector4d::Zero()) {
  const Eigen::Vector3d a = T_w_s.inverse() * a_w, b = T_w_s.inverse() * b_w;
  const Eigen::Vector3d anchor(0.0, 0.0, 1.0);
  Eigen::Vector3d u, w;
  const Eigen::Vector3d d0 = (b - a).normalized();
  TangentAxes(d0, &u, &w);
  const Eigen::Vector3d d = (d0 + e[0] * u + e[1] * w).normalized();
  const Eigen::Vector3d c = 0.5 * (a + b) + e[2] * u + e[3] * w;
  SubmapLine l;
  l.anchor = anchor.cast<float>();
  l.direction = d.cast<float>();
  l.moment = (c - anchor).cross(d).cast<float>();
  const double t = d.dot(c - l.ClosestPoint().cast<double>()), half = 0.5 * (b - a).norm();
  l.t_min = static_cast<float>(t - half);
  l.t_max = static_cast<float>(t + half);
  // dv = e0 u + e1 w; the middle moves by e2 u + e3 w: dn = (c - anchor) x dv + (e2 u + e3 w) x v.
  Eigen::Matrix<double, 6, 4> G = Eigen::Matrix<double, 6, 4>::Zero();
  G.block<3, 1>(0, 0) = (c - anchor).cross(u);
  G.block<3, 1>(0, 1) = (c - anchor).cross(w);
  G.block<3, 1>(0, 2) = u.cross(d);
  G.block<3, 1>(0, 3) = w.cross(d);
  G.block<3, 1>(3, 0) = u;
  G.block<3, 1>(3, 1) = w;
  const Eigen::Vector4d s(sigma_r, sigma_r, sigma_t, sigma_t);
  l.covariance = (G * s.cwiseAbs2().asDiagonal() * G.transpose()).cast<float>();
  l.sightings = 10;
  return l;
}

}  // namespace cairn::testing
