#include "detection/gravity_agreement.h"

#include <cmath>
#include <limits>

#include <Eigen/Geometry>

namespace cairn {
GravityAgreement GravityAgreementOf(const Eigen::Matrix3d& R_frame_a, const Eigen::Matrix3d& R_frame_b,
                                    const Eigen::Matrix3d& R_a_b, const Eigen::Matrix3d& rotation_covariance,
                                    double attitude_sigma) {
  const Eigen::Vector3d up_a = R_frame_a.transpose().col(2);  // the frame's z in body a
  const Eigen::Vector3d up_b = R_frame_b.transpose().col(2);
  const Eigen::Vector3d w = R_a_b * up_b;   // b's up as the sighting puts it in a
  const Eigen::Vector3d v = up_a.cross(w);  // the tilt error: its length is the angle's sine
  GravityAgreement out;
  out.angle = std::atan2(v.norm(), up_a.dot(w));
  // First order: a rotation delta of the sighting moves w by -R_a_b [up_b]x delta; each robot's
  // attitude error moves its up perpendicular to itself.
  Eigen::Matrix3d J;
  for (int k = 0; k < 3; ++k) J.col(k) = -up_a.cross(R_a_b * up_b.cross(Eigen::Vector3d::Unit(k)));
  const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - up_a * up_a.transpose();
  const Eigen::Matrix3d S3 =
      J * rotation_covariance * J.transpose() + 2.0 * attitude_sigma * attitude_sigma * P;
  // In the plane perpendicular to up_a, where v lies.
  Eigen::Matrix<double, 3, 2> B;
  B.col(0) = up_a.unitOrthogonal();
  B.col(1) = up_a.cross(B.col(0));
  const Eigen::Vector2d v2 = B.transpose() * v;
  const Eigen::Matrix2d S = B.transpose() * S3 * B;
  if (v.norm() < 1e-12) {  // aligned, or upside down
    out.mahalanobis2 = out.angle < 1.0 ? 0.0 : std::numeric_limits<double>::infinity();
    return out;
  }
  // v's length saturates at 1 (sine) beyond 90 deg; the angle itself goes on growing.
  const double scale = out.angle / v.norm();
  out.mahalanobis2 = scale * scale * v2.dot(S.ldlt().solve(v2));
  return out;
}

}  // namespace cairn
