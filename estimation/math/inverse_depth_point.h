#pragma once
// A point stored as the camera centre that first saw it (the anchor), the direction of that sighting
// and the inverse of the distance along it. A single view fixes the direction to a pixel's accuracy
// but says nothing about the distance; a Gaussian on the inverse distance covers everything from a
// few metres to infinity, and the projection into later cameras stays close to linear in it, so an
// EKF can take the point from its first sighting (no delayed triangulation) and stay consistent.
//
// State (6): anchor x0 (world, m), azimuth theta (rad, about world z from world x), elevation phi (rad,
// above the world xy plane), inverse distance rho (1/m). The point is p = x0 + m(theta, phi) / rho with
// m = (cos phi cos theta, cos phi sin theta, sin phi). The azimuth's variance grows as 1 / cos^2 phi and
// is undefined for a vertical ray, so a nadir camera should not anchor points at its image centre.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

class InverseDepthPoint {
 public:
  using Vector6 = Eigen::Matrix<double, 6, 1>;
  using Matrix6 = Eigen::Matrix<double, 6, 6>;
  using Matrix36 = Eigen::Matrix<double, 3, 6>;
  using Matrix26 = Eigen::Matrix<double, 2, 6>;

  InverseDepthPoint() = default;
  explicit InverseDepthPoint(const Vector6& state) : state_(state) {}
  // `ray_w` need not be unit length; rho = 0 is a point at infinity.
  InverseDepthPoint(const Eigen::Vector3d& anchor_w, const Eigen::Vector3d& ray_w, double rho);

  // Undelayed initialization from one monocular sighting: the normalized image point (x/z, y/z) with
  // isotropic noise `sigma_xy` (pixel sigma / f) fixes the angles, the prior (rho_init, sigma_rho)
  // the inverse distance. The anchor carries `anchor_cov` (the camera position's, world); cross terms
  // with a filtered camera pose are the caller's, who owns that pose.
  static InverseDepthPoint FromObservation(const Eigen::Isometry3d& T_w_c, const Eigen::Vector2d& xy,
                                           double sigma_xy, double rho_init, double sigma_rho, Matrix6* cov,
                                           const Eigen::Matrix3d& anchor_cov = Eigen::Matrix3d::Zero());
  // A triangulated stereo point `p_c` (camera frame, covariance `cov_c`) anchored at that camera; the
  // anchor is exact (its rows of `cov` are zero) as the point is relative to the camera's pose.
  static InverseDepthPoint FromStereo(const Eigen::Isometry3d& T_w_c, const Eigen::Vector3d& p_c,
                                      const Eigen::Matrix3d& cov_c, Matrix6* cov);
  // The Euclidean point `p_w` re-expressed about `anchor_w` (no covariance: for tests and conversions
  // of exact points).
  static InverseDepthPoint FromEuclidean(const Eigen::Vector3d& anchor_w, const Eigen::Vector3d& p_w);

  const Vector6& state() const { return state_; }
  Vector6& mutable_state() { return state_; }
  Eigen::Vector3d anchor() const { return state_.head<3>(); }
  double theta() const { return state_(3); }
  double phi() const { return state_(4); }
  double rho() const { return state_(5); }
  // Unit direction m(theta, phi) from the anchor, world frame.
  Eigen::Vector3d Ray() const;

  // x0 + m / rho and its Jacobian with respect to the state. Meaningless at rho = 0 (returns inf).
  Eigen::Vector3d Euclidean(Matrix36* J = nullptr) const;

  // Normalized image point (x/z, y/z) in camera T_w_c and its Jacobian with respect to the state.
  // Computed from rho * (p - t), which stays finite at rho = 0. False when the point is not in front of
  // the camera (the outputs are then untouched).
  bool Project(const Eigen::Isometry3d& T_w_c, Eigen::Vector2d* xy, Matrix26* H = nullptr) const;
  // The same in pixels of a pinhole camera (focal length f, principal point cx, cy).
  bool ProjectPixels(const Eigen::Isometry3d& T_w_c, double f, double cx, double cy, Eigen::Vector2d* uv,
                     Matrix26* H = nullptr) const;

  // How far from linear the projection into camera T_w_c would be if this point were held in
  // Euclidean form with the covariance `cov` propagates to: along any direction the projection is a
  // ratio of linear functions, so the second-order term of a 2-sigma step divided by its first-order
  // term is exactly 2 sigma_z / z, maximal along the direction of largest depth spread (sigma_z the
  // standard deviation of the point's depth along the camera's optical axis, z that depth). Seen from
  // the anchor right after an undelayed initialization it is about 2 sigma_rho / rho (4 for the
  // ground robot's 0.1 +- 0.2 1/m); below about 0.1 an EKF on the Euclidean point linearizes
  // about as well, so the point may be converted (three states fewer). Infinite when rho <= 0 or the
  // point is not in front of the camera.
  double EuclideanLinearityIndex(const Matrix6& cov, const Eigen::Isometry3d& T_w_c) const;

 private:
  Vector6 state_ = Vector6::Zero();
};

}  // namespace cairn
