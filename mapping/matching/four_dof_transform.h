#pragma once
// A rigid motion with the four degrees of freedom left between gravity-aligned frames (thesis 6.1):
// translation x, y, z and a rotation by `yaw` about the common z axis (roll = pitch = 0). Submap
// origins are gravity aligned, so every submap-to-submap transform is one of these.

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/status.h"

namespace cairn {

// `a` mapped into (-pi, pi].
double WrapAngle(double a);

class FourDofTransform {
 public:
  FourDofTransform() = default;  // identity
  FourDofTransform(const Eigen::Vector3d& translation, double yaw);
  FourDofTransform(double x, double y, double z, double yaw) : FourDofTransform({x, y, z}, yaw) {}

  // The yaw (z-y-x Euler, atan2(R10, R00)) and translation of `T`, refused (kInvalidArgument) when
  // its rotation is not orthonormal, it is not finite, or it tilts z by more than `max_tilt` rad.
  static Expected<FourDofTransform> FromIsometry(const Eigen::Isometry3d& T, double max_tilt = 1e-6);
  // The same without refusing; the tilt (angle between R * z and z, rad) goes to `tilt` if given.
  static FourDofTransform ProjectIsometry(const Eigen::Isometry3d& T, double* tilt = nullptr);
  // Angle between R * z and z, i.e. the combined roll and pitch, rad.
  static double TiltOf(const Eigen::Matrix3d& R);

  Eigen::Isometry3d ToIsometry() const;
  Eigen::Matrix3d rotation() const;
  // (x, y, z, yaw): the order of the matcher's covariances.
  Eigen::Vector4d ToVector() const { return {t_.x(), t_.y(), t_.z(), yaw_}; }

  const Eigen::Vector3d& translation() const { return t_; }
  double x() const { return t_.x(); }
  double y() const { return t_.y(); }
  double z() const { return t_.z(); }
  double yaw() const { return yaw_; }  // rad, in (-pi, pi]
  double cos_yaw() const { return c_; }
  double sin_yaw() const { return s_; }

  // R p + t.
  Eigen::Vector3d operator*(const Eigen::Vector3d& p) const {
    return {c_ * p.x() - s_ * p.y() + t_.x(), s_ * p.x() + c_ * p.y() + t_.y(), p.z() + t_.z()};
  }
  // T_a_c = T_a_b * T_b_c.
  FourDofTransform operator*(const FourDofTransform& other) const;
  FourDofTransform inverse() const;

 private:
  Eigen::Vector3d t_ = Eigen::Vector3d::Zero();
  double yaw_ = 0.0;
  double c_ = 1.0;  // cos(yaw_), sin(yaw_): applied to every point of a cloud, so computed once
  double s_ = 0.0;
};

}  // namespace cairn
