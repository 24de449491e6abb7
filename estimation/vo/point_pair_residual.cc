#include "estimation/vo/point_pair_residual.h"

#include <Eigen/Geometry>

#include "estimation/math/so3.h"

namespace cairn {

bool PointPairResidual::Evaluate(double const* const* parameters, double* residuals, double** jacobians) const {
  const Eigen::Map<const Eigen::Quaterniond> q(parameters[0]);
  const Eigen::Map<const Eigen::Vector3d> t(parameters[1]);
  // R(q) p = p + 2 w (v x p) + 2 v x (v x p) for a unit quaternion (w, v). Its derivative along
  // the unit sphere, the only directions the quaternion manifold moves in, is the true one.
  const double w = q.w();
  const Eigen::Vector3d v = q.vec();
  const Eigen::Vector3d& p = cur_;
  const Eigen::Vector3d vxp = v.cross(p);
  const Eigen::Vector3d Rp = p + 2.0 * w * vxp + 2.0 * v.cross(vxp);
  Eigen::Map<Eigen::Vector3d> r(residuals);
  r = whiten_ * (Rp + t - kf_);
  if (jacobians == nullptr) return true;
  if (jacobians[0] != nullptr) {
    Eigen::Matrix<double, 3, 4> dRp;  // columns x, y, z, w
    dRp.leftCols<3>() = -2.0 * w * so3::Skew(p) +
                        2.0 * (v.dot(p) * Eigen::Matrix3d::Identity() + v * p.transpose() - 2.0 * p * v.transpose());
    dRp.col(3) = 2.0 * vxp;
    Eigen::Map<Eigen::Matrix<double, 3, 4, Eigen::RowMajor>> J(jacobians[0]);
    J = whiten_ * dRp;
  }
  if (jacobians[1] != nullptr) {
    Eigen::Map<Eigen::Matrix<double, 3, 3, Eigen::RowMajor>> J(jacobians[1]);
    J = whiten_;
  }
  return true;
}

}  // namespace cairn
