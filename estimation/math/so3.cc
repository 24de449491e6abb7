#include "estimation/math/so3.h"

#include <cmath>

namespace cairn::so3 {

Eigen::Matrix3d Skew(const Eigen::Vector3d& w) {
  Eigen::Matrix3d s;
  s << 0.0, -w.z(), w.y(),
       w.z(), 0.0, -w.x(),
       -w.y(), w.x(), 0.0;
  return s;
}

Eigen::Quaterniond ExpQuaternion(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const double theta = std::sqrt(theta2);
  double real, imag_scale;
  if (theta < 1e-5) {
    // Taylor terms to fourth order keep double precision for tiny angles.
    real = 1.0 - theta2 / 8.0 + theta2 * theta2 / 384.0;
    imag_scale = 0.5 - theta2 / 48.0 + theta2 * theta2 / 3840.0;
  } else {
    real = std::cos(0.5 * theta);
    imag_scale = std::sin(0.5 * theta) / theta;
  }
  Eigen::Quaterniond q(real, imag_scale * w.x(), imag_scale * w.y(), imag_scale * w.z());
  return q.normalized();
}

Eigen::Quaterniond ExpQuaternionSmall(const Eigen::Vector3d& w) {
  const double t2 = w.squaredNorm();
  if (t2 >= 1e-4) return ExpQuaternion(w);
  const double x2 = 0.25 * t2;  // (theta / 2)^2
  // Horner form; the constants are reciprocals (a division per term would dominate).
  const double real = 1.0 - x2 * 0.5 * (1.0 - x2 * (1.0 / 12.0) * (1.0 - x2 * (1.0 / 30.0) * (1.0 - x2 * (1.0 / 56.0))));
  const double imag =
      0.5 * (1.0 - x2 * (1.0 / 6.0) * (1.0 - x2 * (1.0 / 20.0) * (1.0 - x2 * (1.0 / 42.0) * (1.0 - x2 * (1.0 / 72.0)))));
  return Eigen::Quaterniond(real, imag * w.x(), imag * w.y(), imag * w.z());
}

Eigen::Quaterniond RetractSmall(const Eigen::Quaterniond& q, const Eigen::Vector3d& w) {
  return Normalized(q * ExpQuaternionSmall(w));
}

Eigen::Matrix3d Exp(const Eigen::Vector3d& w) { return ExpQuaternion(w).toRotationMatrix(); }

Eigen::Vector3d Log(const Eigen::Quaterniond& q_in) {
  Eigen::Quaterniond q = q_in.normalized();
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();  // shortest rotation, angle in [0, pi]
  const Eigen::Vector3d v = q.vec();
  const double sin_half = v.norm();
  if (sin_half < 1e-10) {
    return 2.0 * v / q.w();  // first order is exact to double precision here
  }
  const double theta = 2.0 * std::atan2(sin_half, q.w());
  return theta / sin_half * v;
}

Eigen::Vector3d Log(const Eigen::Matrix3d& R) { return Log(Eigen::Quaterniond(R)); }

Eigen::Matrix3d RightJacobian(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const Eigen::Matrix3d W = Skew(w);
  if (theta2 < 1e-10) return Eigen::Matrix3d::Identity() - 0.5 * W + W * W / 6.0;
  const double theta = std::sqrt(theta2);
  return Eigen::Matrix3d::Identity() - (1.0 - std::cos(theta)) / theta2 * W +
         (theta - std::sin(theta)) / (theta2 * theta) * W * W;
}

Eigen::Matrix3d RightJacobianInverse(const Eigen::Vector3d& w) {
  const double theta2 = w.squaredNorm();
  const Eigen::Matrix3d W = Skew(w);
  if (theta2 < 1e-10) return Eigen::Matrix3d::Identity() + 0.5 * W + W * W / 12.0;
  const double theta = std::sqrt(theta2);
  return Eigen::Matrix3d::Identity() + 0.5 * W +
         (1.0 / theta2 - (1.0 + std::cos(theta)) / (2.0 * theta * std::sin(theta))) * W * W;
}

}  // namespace cairn::so3
