// The filter's small Cholesky against Eigen's LLT, its solves against the products they invert,
// and refusal of matrices that are not positive definite.

#include "estimation/math/small_cholesky.h"

#include <cmath>
#include <limits>

#include <Eigen/Cholesky>
#include <gtest/gtest.h>

namespace cairn {
namespace {

using Matrix6 = Eigen::Matrix<double, 6, 6>;
using Vector6 = Eigen::Matrix<double, 6, 1>;

Matrix6 Spd(unsigned seed) {
  std::srand(seed);
  const Matrix6 A = Matrix6::Random();
  return A * A.transpose() + 0.1 * Matrix6::Identity();
}

TEST(SmallCholeskyTest, FactorMatchesEigenAndTheSolvesInvertTheProducts) {
  for (unsigned seed = 1; seed <= 5; ++seed) {
    const Matrix6 S = Spd(seed);
    Matrix6 L;
    ASSERT_TRUE(small_cholesky::Factor<6>(S, &L));
    const Matrix6 reference = Eigen::LLT<Matrix6>(S).matrixL();
    EXPECT_LT((L - reference).cwiseAbs().maxCoeff(), 1e-12);
    EXPECT_EQ(L.triangularView<Eigen::StrictlyUpper>().toDenseMatrix().cwiseAbs().maxCoeff(), 0.0);

    const Vector6 b = Vector6::LinSpaced(-1.0, 2.0);
    Vector6 z = b;
    small_cholesky::SolveLower<6>(L, z);
    EXPECT_LT((L * z - b).norm(), 1e-12);
    Vector6 y = b;
    small_cholesky::SolveLowerTransposed<6>(L, y);
    EXPECT_LT((L.transpose() * y - b).norm(), 1e-12);
    Eigen::Matrix<double, 4, 6> W = Eigen::Matrix<double, 4, 6>::Random();
    const Eigen::Matrix<double, 4, 6> W0 = W;
    small_cholesky::SolveLowerTransposedRight<4, 6>(L, W);
    EXPECT_LT((W * L.transpose() - W0).cwiseAbs().maxCoeff(), 1e-12);
  }
}

TEST(SmallCholeskyTest, RejectsIndefiniteSingularAndNonFiniteMatrices) {
  Eigen::Matrix3d S = Eigen::Matrix3d::Identity();
  EXPECT_TRUE(small_cholesky::PositiveDefinite<3>(S));
  S(2, 2) = 0.0;
  EXPECT_FALSE(small_cholesky::PositiveDefinite<3>(S));
  S(2, 2) = -1.0;
  EXPECT_FALSE(small_cholesky::PositiveDefinite<3>(S));
  S = Eigen::Matrix3d::Identity();
  S(1, 0) = S(0, 1) = 2.0;  // symmetric, eigenvalues 3 and -1
  EXPECT_FALSE(small_cholesky::PositiveDefinite<3>(S));
  S = Eigen::Matrix3d::Identity();
  S(1, 1) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(small_cholesky::PositiveDefinite<3>(S));
  S(1, 1) = std::numeric_limits<double>::infinity();
  EXPECT_FALSE(small_cholesky::PositiveDefinite<3>(S));
  Eigen::Matrix<double, 1, 1> one;
  one << 4.0;
  Eigen::Matrix<double, 1, 1> l;
  ASSERT_TRUE(small_cholesky::Factor<1>(one, &l));
  EXPECT_EQ(l(0, 0), 2.0);
}

}  // namespace
}  // namespace cairn
