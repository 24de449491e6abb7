#include "estimation/graph/pose_cost_functions.h"

#include <ceres/manifold.h>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

using RowJacobian6 = Eigen::Matrix<double, 6, 7, Eigen::RowMajor>;

Eigen::Quaterniond QuaternionOf(const double* p) { return Eigen::Quaterniond(p[6], p[3], p[4], p[5]); }

// pinv of dq/dphi, phi the rotation vector of the left increment. Ceres' quaternion tangent is
// half of it (Exp(delta) = [sin|delta| delta/|delta|, cos|delta|]), so dq/dphi = P / 2 with P
// the manifold's PlusJacobian, whose columns are orthogonal with norm |q|: pinv = P^T / (|q|^2 / 2).
Eigen::Matrix<double, 3, 4> PlusJacobianPseudoInverse(const double* p) {
  Eigen::Matrix<double, 4, 3, Eigen::RowMajor> P;
  ceres::EigenQuaternionManifold().PlusJacobian(p + 3, P.data());
  return P.transpose() / (0.5 * Eigen::Map<const Eigen::Vector4d>(p + 3).squaredNorm());
}

// Writes [J_t | J_rot * pinv(P)] for a residual with tangent Jacobian J (M x 6) into `out` (M x 7).
template <int M>
void ToAmbient(const Eigen::Matrix<double, M, 6>& J, const double* p, double* out) {
  Eigen::Map<Eigen::Matrix<double, M, 7, Eigen::RowMajor>> A(out);
  A.template leftCols<3>() = J.template leftCols<3>();
  A.template rightCols<4>() = J.template rightCols<3>() * PlusJacobianPseudoInverse(p);
}

}  // namespace

RelativePoseCost::RelativePoseCost(const Pose3& T_i_j, const Matrix6d& information)
    : t_ij_(T_i_j.t), q_ji_(T_i_j.q.conjugate()), sqrt_info_(information.llt().matrixU()) {}

bool RelativePoseCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const double* pi = parameters[0];
  const double* pj = parameters[1];
  const Eigen::Quaterniond qi = QuaternionOf(pi).normalized(), qj = QuaternionOf(pj).normalized();
  const Eigen::Vector3d d = Eigen::Vector3d(pj[0] - pi[0], pj[1] - pi[1], pj[2] - pi[2]);
  const Eigen::Matrix3d Ri_T = qi.conjugate().toRotationMatrix();
  const Eigen::Matrix3d Rji = q_ji_.toRotationMatrix();
  Vector6d e;
  e.head<3>() = Rji * (Ri_T * d - t_ij_);
  e.tail<3>() = so3::Log(q_ji_ * qi.conjugate() * qj);
  Eigen::Map<Vector6d>{residuals} = sqrt_info_ * e;
  if (jacobians == nullptr) return true;
  // Left perturbations t' = t + dt, R' = Exp(phi) R:
  //   de_t/dt_i = -R_ji R_i^T, de_t/dt_j = R_ji R_i^T, de_t/dphi_i = R_ji R_i^T [d]x;
  //   de_r/dphi_j = Jr^-1(e_r) R_j^T = -de_r/dphi_i.
  const Eigen::Matrix3d A = Rji * Ri_T;
  const Eigen::Matrix3d B = so3::RightJacobianInverse(e.tail<3>()) * qj.conjugate().toRotationMatrix();
  if (jacobians[0] != nullptr) {
    Matrix6d J = Matrix6d::Zero();
    J.topLeftCorner<3, 3>() = -A;
    J.topRightCorner<3, 3>() = A * so3::Skew(d);
    J.bottomRightCorner<3, 3>() = -B;
    ToAmbient<6>(sqrt_info_ * J, pi, jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Matrix6d J = Matrix6d::Zero();
    J.topLeftCorner<3, 3>() = A;
    J.bottomRightCorner<3, 3>() = B;
    ToAmbient<6>(sqrt_info_ * J, pj, jacobians[1]);
  }
  return true;
}

ChordalCost::ChordalCost(const Pose3& T_i_j, double kappa, double tau)
    : t_ij_(T_i_j.t), q_ji_(T_i_j.q.conjugate()), sqrt_8kappa_(std::sqrt(8.0 * kappa)), sqrt_tau_(std::sqrt(tau)) {}

bool ChordalCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const double* pi = parameters[0];
  const double* pj = parameters[1];
  const Eigen::Quaterniond qi = QuaternionOf(pi).normalized(), qj = QuaternionOf(pj).normalized();
  const Eigen::Vector3d d = Eigen::Vector3d(pj[0] - pi[0], pj[1] - pi[1], pj[2] - pi[2]);
  const Eigen::Matrix3d Ri_T = qi.conjugate().toRotationMatrix();
  Eigen::Quaterniond qe = q_ji_ * qi.conjugate() * qj;
  if (qe.w() < 0.0) qe.coeffs() = -qe.coeffs();
  Eigen::Map<Vector6d> r(residuals);
  r.head<3>() = sqrt_tau_ * (Ri_T * d - t_ij_);
  r.tail<3>() = sqrt_8kappa_ * qe.vec();
  if (jacobians == nullptr) return true;
  // Left perturbations t' = t + dt, R' = Exp(phi) R:
  //   dr_t/dt_j = -dr_t/dt_i = R_i^T, dr_t/dphi_i = R_i^T [d]x;
  //   q_e' = q_e * exp(R_j^T (phi_j - phi_i) / 2), so dr_R/dphi_j = -dr_R/dphi_i = (w I + [v]x) R_j^T / 2.
  const Eigen::Matrix3d A = sqrt_tau_ * Ri_T;
  const Eigen::Matrix3d B = (0.5 * sqrt_8kappa_) * (qe.w() * Eigen::Matrix3d::Identity() + so3::Skew(qe.vec())) *
                            qj.conjugate().toRotationMatrix();
  if (jacobians[0] != nullptr) {
    Matrix6d J = Matrix6d::Zero();
    J.topLeftCorner<3, 3>() = -A;
    J.topRightCorner<3, 3>() = A * so3::Skew(d);
    J.bottomRightCorner<3, 3>() = -B;
    ToAmbient<6>(J, pi, jacobians[0]);
  }
  if (jacobians[1] != nullptr) {
    Matrix6d J = Matrix6d::Zero();
    J.topLeftCorner<3, 3>() = A;
    J.bottomRightCorner<3, 3>() = B;
    ToAmbient<6>(J, pj, jacobians[1]);
  }
  return true;
}

AbsolutePoseCost::AbsolutePoseCost(const Pose3& Z, const Matrix6d& information)
    : t_(Z.t), q_inv_(Z.q.conjugate()), sqrt_info_(information.llt().matrixU()) {}

bool AbsolutePoseCost::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const double* p = parameters[0];
  const Eigen::Quaterniond q = QuaternionOf(p).normalized();
  const Eigen::Matrix3d Rz_T = q_inv_.toRotationMatrix();
  Vector6d e;
  e.head<3>() = Rz_T * (Eigen::Vector3d(p[0], p[1], p[2]) - t_);
  e.tail<3>() = so3::Log(q_inv_ * q);
  Eigen::Map<Vector6d>{residuals} = sqrt_info_ * e;
  if (jacobians == nullptr || jacobians[0] == nullptr) return true;
  // Rz^T Exp(phi) R = (Rz^T R) Exp(R^T phi).
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = Rz_T;
  J.bottomRightCorner<3, 3>() = so3::RightJacobianInverse(e.tail<3>()) * q.conjugate().toRotationMatrix();
  ToAmbient<6>(sqrt_info_ * J, p, jacobians[0]);
  return true;
}

}  // namespace cairn
