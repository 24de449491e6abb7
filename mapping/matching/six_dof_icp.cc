#include "mapping/matching/six_dof_icp.h"

#include <algorithm>
#include <cmath>

#include "estimation/math/so3.h"
#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

using Vector6d = Eigen::Matrix<double, 6, 1>;
using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct SixDofModel {
  static constexpr int kDof = 6;
  using Transform = Eigen::Isometry3d;
  static constexpr const char* kParameters = "x, y, z, roll, pitch, yaw";

  static Eigen::Vector3d Translation(const Transform& T) { return T.translation(); }
  static bool Finite(const Transform& T) { return T.matrix().allFinite(); }
  static Vector6d Jacobian(const Eigen::Vector3d& n, const Eigen::Vector3d& v) {
    Vector6d J;
    J << n, v.cross(n);
    return J;
  }
  static Transform Step(const Transform& T, const Vector6d& step) {
    Transform out = Transform::Identity();
    // Re-orthonormalized through a quaternion, so rounding does not accumulate over iterations.
    out.linear() = Eigen::Quaterniond(so3::Exp(step.tail<3>()) * T.linear()).normalized().toRotationMatrix();
    out.translation() = T.translation() + step.head<3>();
    return out;
  }
  static double RotationChange(const Transform& a, const Transform& b) {
    return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle();
  }

  // As the 4-DoF model's, with the rotations about the centroid c of the paired points, scaled
  // by their RMS distance from it.
  static double Observability(const IcpPass<6>& pass, const Transform& T) {
    if (pass.n == 0) return 0.0;
    const double n = static_cast<double>(pass.n);
    const Eigen::Vector3d c = pass.sum_q / n;
    const double L2 = (pass.sum_qh2 + pass.sum_qz2) / n - c.squaredNorm();
    if (!(L2 > 1e-12)) return 0.0;
    // J_c = M J: dr/d(w about c) = ((R p) - w) x n = dr/dw - w x n, with w = c - t.
    const Eigen::Vector3d w = c - T.translation();
    Matrix6d M = Matrix6d::Identity();
    M.block<3, 3>(3, 0) = -so3::Skew(w);
    const Matrix6d Hc = M * pass.H * M.transpose();
    Vector6d scale;
    scale << 1.0, 1.0, 1.0, Eigen::Vector3d::Constant(1.0 / std::sqrt(L2));
    Matrix6d Hs = scale.asDiagonal() * Hc * scale.asDiagonal();
    Hs /= n;
    Vector6d values;
    Matrix6d vectors;
    if (!SymmetricEigen(Hs, &values, &vectors)) return 0.0;
    return std::max(0.0, values(0));
  }
};

}  // namespace

SixDofIcpResult SixDofIcp::Align(std::span<const Eigen::Vector3d> target_a, std::span<const Eigen::Vector3d> source_b,
                                 const Eigen::Isometry3d& T_a_b_initial) const {
  return AlignPointToPlane<SixDofModel>(options_, target_a, source_b, T_a_b_initial);
}

}  // namespace cairn
