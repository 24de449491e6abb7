#include "estimation/math/so3.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimation/math/ordered_draws.h"

namespace cairn {
namespace {

TEST(So3Test, ExpLogRoundTripFromTinyToNearPi) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (double angle : {1e-12, 1e-7, 1e-3, 0.5, 2.0, 3.1, M_PI - 1e-6}) {
    for (int i = 0; i < 20; ++i) {
      const Eigen::Vector3d axis = DrawVector3(n, rng).normalized();
      const Eigen::Vector3d w = angle * axis;
      EXPECT_LT((so3::Log(so3::Exp(w)) - w).norm(), 1e-9 * std::max(1.0, angle)) << angle;
    }
  }
}

TEST(So3Test, ExpMatchesEigenAngleAxis) {
  const Eigen::Vector3d w(0.3, -1.1, 0.7);
  const Eigen::Matrix3d ref = Eigen::AngleAxisd(w.norm(), w.normalized()).toRotationMatrix();
  EXPECT_LT((so3::Exp(w) - ref).norm(), 1e-14);
  EXPECT_LT((so3::Skew(w) * Eigen::Vector3d(1, 2, 3) - w.cross(Eigen::Vector3d(1, 2, 3))).norm(), 1e-15);
}

TEST(So3Test, RightJacobianLinearizesExp) {
  for (const Eigen::Vector3d& w : {Eigen::Vector3d(1e-8, 0, 0), Eigen::Vector3d(0.4, -0.2, 1.3)}) {
    const Eigen::Matrix3d Jr = so3::RightJacobian(w);
    EXPECT_LT((Jr * so3::RightJacobianInverse(w) - Eigen::Matrix3d::Identity()).norm(), 1e-9);
    const Eigen::Vector3d dw(1e-6, -2e-6, 0.5e-6);
    const Eigen::Matrix3d lhs = so3::Exp(w + dw);
    const Eigen::Matrix3d rhs = so3::Exp(w) * so3::Exp(Jr * dw);
    EXPECT_LT((lhs - rhs).norm(), 1e-11);
  }
}

}  // namespace
}  // namespace cairn
