// The pose refinement's point-pair residual: value against the rotation matrix, and Jacobians
// against central differences, composed with the quaternion manifold's PlusJacobian (the only
// directions the solver moves the quaternion in) and for t directly.

#include "estimation/vo/point_pair_residual.h"

#include <ceres/manifold.h>
#include <gtest/gtest.h>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

TEST(PointPairResidualTest, ValueAndJacobiansMatchTheRotationAndNumericDifferences) {
  const Eigen::Vector3d kf(0.4, -1.2, 6.5), cur(0.1, -0.9, 6.8);
  Eigen::Matrix3d W;
  W << 2.0, 0.0, 0.0, -0.3, 1.5, 0.0, 0.2, 0.1, 0.7;
  const PointPairResidual cost(kf, cur, W);
  const ceres::EigenQuaternionManifold manifold;
  for (const Eigen::Vector3d& rv : {Eigen::Vector3d(0.0, 0.0, 0.0), Eigen::Vector3d(0.02, -0.05, 0.01),
                                    Eigen::Vector3d(1.1, -0.4, 2.3), Eigen::Vector3d(0.0, 3.1, 0.0)}) {
    const Eigen::Quaterniond q = so3::ExpQuaternion(rv);
    const Eigen::Vector3d t(0.3, -0.2, 0.05);
    const double* params[2] = {q.coeffs().data(), t.data()};
    Eigen::Vector3d r;
    Eigen::Matrix<double, 3, 4, Eigen::RowMajor> Jq;
    Eigen::Matrix<double, 3, 3, Eigen::RowMajor> Jt;
    double* jac[2] = {Jq.data(), Jt.data()};
    ASSERT_TRUE(cost.Evaluate(params, r.data(), jac));
    const Eigen::Vector3d expected = W * (q.toRotationMatrix() * cur + t - kf);
    EXPECT_LT((r - expected).norm(), 1e-12);

    auto eval = [&](const Eigen::Quaterniond& qq, const Eigen::Vector3d& tt) {
      const double* p[2] = {qq.coeffs().data(), tt.data()};
      Eigen::Vector3d out;
      EXPECT_TRUE(cost.Evaluate(p, out.data(), nullptr));
      return out;
    };
    Eigen::Matrix<double, 4, 3, Eigen::RowMajor> plus;
    ASSERT_TRUE(manifold.PlusJacobian(q.coeffs().data(), plus.data()));
    const Eigen::Matrix3d analytic_q = Jq * plus;
    const double h = 1e-6;
    for (int k = 0; k < 3; ++k) {
      Eigen::Vector3d d = Eigen::Vector3d::Zero();
      d(k) = h;
      Eigen::Quaterniond qp, qm;
      manifold.Plus(q.coeffs().data(), d.data(), qp.coeffs().data());
      d(k) = -h;
      manifold.Plus(q.coeffs().data(), d.data(), qm.coeffs().data());
      const Eigen::Vector3d numeric_q = (eval(qp, t) - eval(qm, t)) / (2.0 * h);
      EXPECT_LT((analytic_q.col(k) - numeric_q).norm(), 1e-6) << "rotation column " << k << " at " << rv.transpose();
      Eigen::Vector3d tp = t, tm = t;
      tp(k) += h;
      tm(k) -= h;
      const Eigen::Vector3d numeric_t = (eval(q, tp) - eval(q, tm)) / (2.0 * h);
      EXPECT_LT((Jt.col(k) - numeric_t).norm(), 1e-6) << "translation column " << k;
    }
  }
}

}  // namespace
}  // namespace cairn
