#pragma once
// Rotation-group helpers shared by the filter, the odometry and the graph: the exponential and
// logarithm maps of SO(3) and the right Jacobian used to propagate small-angle errors. Rotation
// vectors are axis * angle in rad.

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn::so3 {

// [w]x: Skew(w) * v == w.cross(v).
Eigen::Matrix3d Skew(const Eigen::Vector3d& w);
Eigen::Matrix3d Exp(const Eigen::Vector3d& w);
Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w);
// The same for the small rotations of the filter (IMU steps, error corrections): below 1e-2 rad a
// Taylor series that is exact to double precision (and of unit norm to it) avoids the
// trigonometric functions and the normalization.
Eigen::Quaterniond ExpQuaternionSmall(const Eigen::Vector3d& w);
// q * Exp(w) for a small w, renormalized.
Eigen::Quaterniond RetractSmall(const Eigen::Quaterniond& q, const Eigen::Vector3d& w);
// q normalized with one square root and one division (Eigen's divides every coefficient).
inline Eigen::Quaterniond Normalized(const Eigen::Quaterniond& q) {
  return Eigen::Quaterniond(q.coeffs() * (1.0 / q.coeffs().norm()));
}
// Rotation vector with angle in [0, pi]; accurate near 0 and near pi.
Eigen::Vector3d Log(const Eigen::Matrix3d& R);
Eigen::Vector3d Log(const Eigen::Quaterniond& q);
// Right Jacobian Jr(w): Exp(w + dw) ~= Exp(w) Exp(Jr(w) dw).
Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& w);
Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& w);

}  // namespace cairn::so3
