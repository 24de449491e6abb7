#pragma once
// A submap origin as the graph places it, for the landmark associators (planes, lines).

#include <cmath>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/math/so3.h"

namespace cairn {

// An origin's pose in the graph's world and its marginal covariance: tangent [translation;
// rotation vector], both in the world's axes, rotation perturbation on the left (the graph's).
struct SubmapPlacement {
  Eigen::Isometry3d T_world_submap = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 6> covariance = Eigen::Matrix<double, 6, 6>::Zero();
};

// T moved by the graph's tangent `delta`: t + dt, Exp(dr) R.
inline Eigen::Isometry3d PerturbedOrigin(const Eigen::Isometry3d& T,
                                         const Eigen::Matrix<double, 6, 1>& delta) {
  Eigen::Isometry3d out = T;
  out.translation() += delta.head<3>();
  out.linear() = so3::Exp(delta.tail<3>()) * T.linear();
  return out;
}

// The squared Mahalanobis distance of a pairing of landmark A of one submap with landmark B of
// another: `error(e_b, d_a, d_b)` is the N-vector of B's landmark against A's, with B's landmark
// moved by its own error coordinates e_b and the origins by the tangents d_a, d_b. Its covariance is
// cov_a + J_b cov_b J_b^T + J_p P J_p^T (A's own error enters with the identity), the Jacobians by
// central differences (a handful of landmarks per submap, so cost is no concern). Negative when that
// covariance is not positive definite or the distance not finite.
template <int N, class ErrorFn>
double PairingChi2(const ErrorFn& error, const Eigen::Matrix<double, N, N>& cov_a,
                   const Eigen::Matrix<double, N, N>& cov_b, const SubmapPlacement& placed_a,
                   const SubmapPlacement& placed_b) {
  using VN = Eigen::Matrix<double, N, 1>;
  using V6 = Eigen::Matrix<double, 6, 1>;
  const V6 zero6 = V6::Zero();
  const VN zeroN = VN::Zero();
  const VN e0 = error(zeroN, zero6, zero6);
  constexpr double h = 1e-6;
  Eigen::Matrix<double, N, N> Jb;
  Eigen::Matrix<double, N, 12> Jp;
  for (int k = 0; k < N; ++k) {
    VN s = zeroN;
    s[k] = h;
    Jb.col(k) = (error(s, zero6, zero6) - error(-s, zero6, zero6)) / (2 * h);
  }
  for (int k = 0; k < 12; ++k) {
    V6 s = zero6;
    s[k % 6] = h;
    Jp.col(k) = k < 6 ? (error(zeroN, s, zero6) - error(zeroN, -s, zero6)) / (2 * h)
                      : (error(zeroN, zero6, s) - error(zeroN, zero6, -s)) / (2 * h);
  }
  Eigen::Matrix<double, 12, 12> P = Eigen::Matrix<double, 12, 12>::Zero();
  P.template topLeftCorner<6, 6>() = placed_a.covariance;
  P.template bottomRightCorner<6, 6>() = placed_b.covariance;
  const Eigen::Matrix<double, N, N> S = cov_a + Jb * cov_b * Jb.transpose() + Jp * P * Jp.transpose();
  const Eigen::LDLT<Eigen::Matrix<double, N, N>> ldlt(0.5 * (S + S.transpose()));
  if (ldlt.info() != Eigen::Success || !(ldlt.vectorD().minCoeff() > 0.0)) return -1.0;
  const double chi2 = e0.dot(ldlt.solve(e0));
  return std::isfinite(chi2) ? chi2 : -1.0;
}

}  // namespace cairn
