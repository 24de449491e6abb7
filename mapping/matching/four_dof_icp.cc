#include "mapping/matching/four_dof_icp.h"

#include <algorithm>
#include <cmath>

#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

struct FourDofModel {
  static constexpr int kDof = 4;
  using Transform = FourDofTransform;
  static constexpr const char* kParameters = "x, y, z, yaw";

  static const Eigen::Vector3d& Translation(const Transform& T) { return T.translation(); }
  static bool Finite(const Transform& T) { return T.translation().allFinite() && std::isfinite(T.yaw()); }
  static Eigen::Vector4d Jacobian(const Eigen::Vector3d& n, const Eigen::Vector3d& v) {
    Eigen::Vector4d J;
    J << n, n.y() * v.x() - n.x() * v.y();  // n . (z x R p)
    return J;
  }
  static Transform Step(const Transform& T, const Eigen::Vector4d& step) {
    return FourDofTransform(T.translation() + step.head<3>(), T.yaw() + step(3));
  }
  static double RotationChange(const Transform& a, const Transform& b) { return std::abs(WrapAngle(a.yaw() - b.yaw())); }

  // The smallest eigenvalue of the per-correspondence information with yaw taken about the
  // centroid of the paired points and scaled by their RMS horizontal distance from it (see the
  // header); 0 when the points have no horizontal extent.
  static double Observability(const IcpPass<4>& pass, const Transform& T) {
    if (pass.n == 0) return 0.0;
    const double n = static_cast<double>(pass.n);
    const Eigen::Vector3d c = pass.sum_q / n;
    const double L2 = pass.sum_qh2 / n - c.head<2>().squaredNorm();
    if (!(L2 > 1e-12)) return 0.0;
    // J_c = M J: dr/d(yaw about c) = dr/d(yaw) - n . w with w = z x (c - t).
    const Eigen::Vector3d ct = c - T.translation();
    const Eigen::Vector3d w(-ct.y(), ct.x(), 0.0);
    Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
    M.block<1, 3>(3, 0) = -w.transpose();
    const Eigen::Matrix4d Hc = M * pass.H * M.transpose();
    const Eigen::Vector4d scale(1.0, 1.0, 1.0, 1.0 / std::sqrt(L2));
    Eigen::Matrix4d Hs = scale.asDiagonal() * Hc * scale.asDiagonal();
    Hs /= n;
    // The compiled 6x6 solver with two padding eigenvalues above all of Hs's (its trace bounds them).
    Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
    A.topLeftCorner<4, 4>() = Hs;
    A(4, 4) = A(5, 5) = Hs.trace() + 1.0;
    Eigen::Matrix<double, 6, 1> values;
    Eigen::Matrix<double, 6, 6> vectors;
    if (!SymmetricEigen(A, &values, &vectors)) return 0.0;
    return std::max(0.0, values(0));
  }
};

}  // namespace

FourDofIcpResult FourDofIcp::Align(std::span<const Eigen::Vector3d> target_a,
                                   std::span<const Eigen::Vector3d> source_b,
                                   const FourDofTransform& T_a_b_initial) const {
  return AlignPointToPlane<FourDofModel>(options_, target_a, source_b, T_a_b_initial);
}

}  // namespace cairn
