#include "mapping/matching/four_dof_transform.h"

#include <cmath>
#include <numbers>
#include <string>

namespace cairn {

double WrapAngle(double a) {
  if (a > -std::numbers::pi && a <= std::numbers::pi) return a;
  a = std::remainder(a, 2.0 * std::numbers::pi);  // [-pi, pi]
  return a <= -std::numbers::pi ? a + 2.0 * std::numbers::pi : a;
}

FourDofTransform::FourDofTransform(const Eigen::Vector3d& translation, double yaw)
    : t_(translation), yaw_(WrapAngle(yaw)), c_(std::cos(yaw_)), s_(std::sin(yaw_)) {}

double FourDofTransform::TiltOf(const Eigen::Matrix3d& R) {
  // The third column is R * z; atan2 stays accurate for small and large tilts alike (acos does not).
  return std::atan2(std::hypot(R(0, 2), R(1, 2)), R(2, 2));
}

FourDofTransform FourDofTransform::ProjectIsometry(const Eigen::Isometry3d& T, double* tilt) {
  const Eigen::Matrix3d R = T.linear();
  if (tilt != nullptr) *tilt = TiltOf(R);
  return FourDofTransform(T.translation(), std::atan2(R(1, 0), R(0, 0)));
}

Expected<FourDofTransform> FourDofTransform::FromIsometry(const Eigen::Isometry3d& T, double max_tilt) {
  const Eigen::Matrix3d R = T.linear();
  if (!R.allFinite() || !T.translation().allFinite())
    return InvalidArgumentError("4-DoF transform from a non-finite isometry");
  const double orthonormality = (R.transpose() * R - Eigen::Matrix3d::Identity()).cwiseAbs().maxCoeff();
  if (orthonormality > 1e-6 || R.determinant() < 0.0)
    return InvalidArgumentError("4-DoF transform from a matrix that is not a rotation (|R^T R - I| = " +
                                std::to_string(orthonormality) + ")");
  double tilt = 0.0;
  const FourDofTransform T4 = ProjectIsometry(T, &tilt);
  if (!(tilt <= max_tilt))
    return InvalidArgumentError("4-DoF transform from an isometry tilted by " + std::to_string(tilt) +
                                " rad (roll/pitch), more than " + std::to_string(max_tilt));
  return T4;
}

Eigen::Matrix3d FourDofTransform::rotation() const {
  Eigen::Matrix3d R;
  R << c_, -s_, 0.0, s_, c_, 0.0, 0.0, 0.0, 1.0;
  return R;
}

Eigen::Isometry3d FourDofTransform::ToIsometry() const {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = rotation();
  T.translation() = t_;
  return T;
}

FourDofTransform FourDofTransform::operator*(const FourDofTransform& other) const {
  return FourDofTransform((*this) * other.t_, yaw_ + other.yaw_);
}

FourDofTransform FourDofTransform::inverse() const {
  // R^T (-t): the rotation about z by -yaw of -t.
  const Eigen::Vector3d t_inv(-(c_ * t_.x() + s_ * t_.y()), -(-s_ * t_.x() + c_ * t_.y()), -t_.z());
  return FourDofTransform(t_inv, -yaw_);
}

}  // namespace cairn
