#include "estimation/graph/pose_factors.h"

#include <random>

#include <gtest/gtest.h>

#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

Pose3 RandomPose(std::mt19937& rng, double scale = 1.0) {
  std::normal_distribution<double> n(0.0, 1.0);
  const Eigen::Vector3d t = DrawVector3(n, rng) * 3.0;
  return {t, so3::ExpQuaternion(scale * DrawVector3(n, rng))};
}

Matrix6d RandomInformation(std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, 1.0);
  Matrix6d A;
  for (int i = 0; i < 36; ++i) A(i) = n(rng);
  return A * A.transpose() + Matrix6d::Identity();
}

// Compares the analytic (autodiff) tangent-space Jacobians of `cost` with central differences
// through the pose manifold's Plus.
void ExpectJacobiansMatchNumeric(const ceres::CostFunction& cost, std::vector<Pose3> poses) {
  const auto manifold = MakePoseManifold();
  const int m = cost.num_residuals();
  std::vector<std::vector<double>> blocks(poses.size(), std::vector<double>(7));
  std::vector<double*> params;
  for (size_t b = 0; b < poses.size(); ++b) {
    PoseToBlock(poses[b], blocks[b].data());
    params.push_back(blocks[b].data());
  }
  std::vector<std::vector<double>> jac(poses.size(), std::vector<double>(static_cast<size_t>(7 * m)));
  std::vector<double*> jac_ptrs;
  for (auto& j : jac) jac_ptrs.push_back(j.data());
  Eigen::VectorXd r0(m);
  ASSERT_TRUE(cost.Evaluate(params.data(), r0.data(), jac_ptrs.data()));
  for (size_t b = 0; b < poses.size(); ++b) {
    Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus_jac;
    manifold->PlusJacobian(blocks[b].data(), plus_jac.data());
    const Eigen::MatrixXd J = Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>>(jac[b].data(), m, 7) * plus_jac;
    const std::vector<double> x0 = blocks[b];
    for (int k = 0; k < 6; ++k) {
      const double h = 1e-6;
      Eigen::Matrix<double, 6, 1> delta = Eigen::Matrix<double, 6, 1>::Zero();
      Eigen::VectorXd rp(m), rm(m);
      delta[k] = h;
      manifold->Plus(x0.data(), delta.data(), blocks[b].data());
      ASSERT_TRUE(cost.Evaluate(params.data(), rp.data(), nullptr));
      delta[k] = -h;
      manifold->Plus(x0.data(), delta.data(), blocks[b].data());
      ASSERT_TRUE(cost.Evaluate(params.data(), rm.data(), nullptr));
      blocks[b] = x0;
      const Eigen::VectorXd numeric = (rp - rm) / (2 * h);
      EXPECT_LT((numeric - J.col(k)).norm(), 1e-6 * std::max(1.0, numeric.norm())) << "block " << b << " dir " << k;
    }
  }
}

// Tangent-space Jacobians (through the manifold's PlusJacobian) and residuals of two cost
// functions on the same poses.
void ExpectSameCost(const ceres::CostFunction& analytic, const ceres::CostFunction& reference,
                    const std::vector<Pose3>& poses) {
  const auto manifold = MakePoseManifold();
  const int m = analytic.num_residuals();
  std::vector<std::vector<double>> blocks(poses.size(), std::vector<double>(7));
  std::vector<const double*> params;
  for (size_t b = 0; b < poses.size(); ++b) {
    PoseToBlock(poses[b], blocks[b].data());
    params.push_back(blocks[b].data());
  }
  auto eval = [&](const ceres::CostFunction& c, Eigen::VectorXd& r, std::vector<Eigen::MatrixXd>& J) {
    std::vector<std::vector<double>> jac(poses.size(), std::vector<double>(static_cast<size_t>(7 * m)));
    std::vector<double*> ptrs;
    for (auto& j : jac) ptrs.push_back(j.data());
    r.resize(m);
    ASSERT_TRUE(c.Evaluate(params.data(), r.data(), ptrs.data()));
    for (size_t b = 0; b < poses.size(); ++b) {
      Eigen::Matrix<double, 7, 6, Eigen::RowMajor> plus;
      manifold->PlusJacobian(blocks[b].data(), plus.data());
      J.push_back(Eigen::Map<Eigen::Matrix<double, Eigen::Dynamic, 7, Eigen::RowMajor>>(jac[b].data(), m, 7) * plus);
    }
  };
  Eigen::VectorXd ra, rr;
  std::vector<Eigen::MatrixXd> Ja, Jr;
  eval(analytic, ra, Ja);
  eval(reference, rr, Jr);
  EXPECT_LT((ra - rr).norm(), 1e-10 * (1 + rr.norm()));
  for (size_t b = 0; b < poses.size(); ++b) EXPECT_LT((Ja[b] - Jr[b]).norm(), 1e-9 * (1 + Jr[b].norm())) << b;
}

TEST(PoseFactorsTest, AnalyticCostsEqualAutodiffOfTheReferenceFunctors) {
  std::mt19937 rng(4);
  for (int trial = 0; trial < 20; ++trial) {
    // Large, small (the series branches) and near-pi rotation errors.
    const double scale = trial % 3 == 0 ? 1.0 : trial % 3 == 1 ? 1e-7 : 0.0;
    const Pose3 a = RandomPose(rng), z = RandomPose(rng, 0.5);
    Pose3 b = a * z * RandomPose(rng, scale);
    if (trial % 5 == 4) b = a * z * Pose3{Eigen::Vector3d(0.1, 0.2, 0.3), so3::ExpQuaternion(Eigen::Vector3d(0, 0, 3.1))};
    const Matrix6d info = RandomInformation(rng);
    std::unique_ptr<ceres::CostFunction> rel(RelativePoseResidual::Create(z, info));
    ceres::AutoDiffCostFunction<RelativePoseResidual, 6, 7, 7> rel_ref(new RelativePoseResidual(z, info));
    ExpectSameCost(*rel, rel_ref, {a, b});
    std::unique_ptr<ceres::CostFunction> chordal(ChordalResidual::Create(z, 3.0, 7.0));
    ceres::AutoDiffCostFunction<ChordalResidual, 6, 7, 7> chordal_ref(new ChordalResidual(z, 3.0, 7.0));
    ExpectSameCost(*chordal, chordal_ref, {a, b});
    std::unique_ptr<ceres::CostFunction> abs(AbsolutePoseResidual::Create(a.Inverse() * b, info));
    ceres::AutoDiffCostFunction<AbsolutePoseResidual, 6, 7> abs_ref(new AbsolutePoseResidual(a.Inverse() * b, info));
    ExpectSameCost(*abs, abs_ref, {z});
  }
}

TEST(PoseFactorsTest, RelativePoseResidualIsTheWeightedGeodesicError) {
  std::mt19937 rng(1);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose3 a = RandomPose(rng), b = RandomPose(rng), z = RandomPose(rng, 0.3);
    const Matrix6d info = RandomInformation(rng);
    std::unique_ptr<ceres::CostFunction> cost(RelativePoseResidual::Create(z, info));
    double pa[7], pb[7];
    PoseToBlock(a, pa);
    PoseToBlock(b, pb);
    const double* params[] = {pa, pb};
    Vector6d r;
    ASSERT_TRUE(cost->Evaluate(params, r.data(), nullptr));
    const Vector6d e = GeodesicError(a, b, z);
    EXPECT_NEAR(r.squaredNorm(), e.dot(info * e), 1e-9 * (1 + r.squaredNorm()));
    ExpectJacobiansMatchNumeric(*cost, {a, b});
  }
  // Zero at the measurement.
  const Pose3 a = RandomPose(rng), b = RandomPose(rng);
  std::unique_ptr<ceres::CostFunction> cost(RelativePoseResidual::Create(a.Inverse() * b, Matrix6d::Identity()));
  double pa[7], pb[7];
  PoseToBlock(a, pa);
  PoseToBlock(b, pb);
  const double* params[] = {pa, pb};
  Vector6d r;
  ASSERT_TRUE(cost->Evaluate(params, r.data(), nullptr));
  EXPECT_LT(r.norm(), 1e-12);
}

TEST(PoseFactorsTest, ChordalResidualIsTheSeSyncTerm) {
  std::mt19937 rng(2);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose3 a = RandomPose(rng), b = RandomPose(rng), z = RandomPose(rng);
    std::unique_ptr<ceres::CostFunction> cost(ChordalResidual::Create(z, 3.0, 7.0));
    double pa[7], pb[7];
    PoseToBlock(a, pa);
    PoseToBlock(b, pb);
    const double* params[] = {pa, pb};
    Vector6d r;
    ASSERT_TRUE(cost->Evaluate(params, r.data(), nullptr));
    const double expected = 3.0 * (b.R() - a.R() * z.R()).squaredNorm() + 7.0 * (b.t - a.t - a.R() * z.t).squaredNorm();
    EXPECT_NEAR(r.squaredNorm(), expected, 1e-9 * expected);
    ExpectJacobiansMatchNumeric(*cost, {a, b});
  }
}

TEST(PoseFactorsTest, AbsoluteFactorsMatchNumericJacobians) {
  std::mt19937 rng(3);
  for (int trial = 0; trial < 10; ++trial) {
    const Pose3 x = RandomPose(rng), z = RandomPose(rng);
    const Matrix6d info = RandomInformation(rng);
    std::unique_ptr<ceres::CostFunction> pose(AbsolutePoseResidual::Create(z, info));
    double p[7];
    PoseToBlock(x, p);
    const double* params[] = {p};
    Vector6d r;
    ASSERT_TRUE(pose->Evaluate(params, r.data(), nullptr));
    const Vector6d e = GeodesicError(Pose3(), x, z);  // prior == relative to the identity
    EXPECT_NEAR(r.squaredNorm(), e.dot(info * e), 1e-9 * (1 + r.squaredNorm()));
    ExpectJacobiansMatchNumeric(*pose, {x});
    const Eigen::Matrix3d pinfo = info.topLeftCorner<3, 3>();
    std::unique_ptr<ceres::CostFunction> position(AbsolutePositionResidual::Create(z.t, pinfo));
    Eigen::Vector3d rp;
    ASSERT_TRUE(position->Evaluate(params, rp.data(), nullptr));
    EXPECT_NEAR(rp.squaredNorm(), (x.t - z.t).dot(pinfo * (x.t - z.t)), 1e-9 * (1 + rp.squaredNorm()));
    ExpectJacobiansMatchNumeric(*position, {x});
  }
}

}  // namespace
}  // namespace cairn
