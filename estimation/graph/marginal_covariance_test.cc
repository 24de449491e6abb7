#include "estimation/graph/marginal_covariance.h"

#include <array>
#include <map>
#include <random>

#include <ceres/ceres.h>
#include <gtest/gtest.h>

#include "estimation/graph/pose_factors.h"
#include "estimation/graph/slam_graph.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

using Matrix6x12d = Eigen::Matrix<double, 6, 12>;

// Random graphs: a chain (connected), random extra edges and one prior; the information is a sum
// of J^T J per factor, so it is positive definite. Compared with the dense inverse.
TEST(MarginalCovarianceTest, MatchesTheDenseInverseOnRandomGraphs) {
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 20; ++trial) {
    const int blocks = 2 + trial * 2;
    std::uniform_int_distribution<int> pick(0, blocks - 1);
    MarginalCovariance mc(blocks);
    Eigen::MatrixXd H = Eigen::MatrixXd::Zero(6 * blocks, 6 * blocks);
    auto add_edge = [&](int i, int j) {
      Matrix6x12d J;
      for (int r = 0; r < 6; ++r) {
        for (int c = 0; c < 12; ++c) J(r, c) = n(rng);
      }
      const Eigen::Matrix<double, 12, 12> JtJ = J.transpose() * J;
      mc.Add(i, i, JtJ.topLeftCorner<6, 6>());
      mc.Add(j, j, JtJ.bottomRightCorner<6, 6>());
      mc.Add(j, i, JtJ.bottomLeftCorner<6, 6>());  // both argument orders must work
      H.block<6, 6>(6 * i, 6 * i) += JtJ.topLeftCorner<6, 6>();
      H.block<6, 6>(6 * j, 6 * j) += JtJ.bottomRightCorner<6, 6>();
      H.block<6, 6>(6 * j, 6 * i) += JtJ.bottomLeftCorner<6, 6>();
      H.block<6, 6>(6 * i, 6 * j) += JtJ.topRightCorner<6, 6>();
      if (trial % 2 == 0) mc.Add(i, j, Matrix6d::Zero());  // an explicit zero block is harmless
    };
    for (int i = 0; i + 1 < blocks; ++i) add_edge(i, i + 1);
    for (int e = 0; e < blocks; ++e) {
      const int i = pick(rng), j = pick(rng);
      if (i != j) add_edge(i, j);
    }
    const int anchor = pick(rng);
    mc.Add(anchor, anchor, 10.0 * Matrix6d::Identity());
    H.block<6, 6>(6 * anchor, 6 * anchor) += 10.0 * Matrix6d::Identity();
    ASSERT_TRUE(mc.Compute().ok()) << trial;
    const Eigen::MatrixXd C = H.inverse();
    for (int i = 0; i < blocks; ++i) {
      const Matrix6d ref = C.block<6, 6>(6 * i, 6 * i);
      EXPECT_LT((mc.Marginal(i) - ref).norm(), 1e-9 * ref.norm()) << "trial " << trial << " block " << i;
    }
  }
}

TEST(MarginalCovarianceTest, RejectsRankDeficientInformation) {
  // Two poses tied only to each other: the common motion is unobservable.
  MarginalCovariance relative_only(2);
  Matrix6x12d J;
  J << Matrix6d::Identity(), -Matrix6d::Identity();
  const Eigen::Matrix<double, 12, 12> JtJ = J.transpose() * J;
  relative_only.Add(0, 0, JtJ.topLeftCorner<6, 6>());
  relative_only.Add(1, 1, JtJ.bottomRightCorner<6, 6>());
  relative_only.Add(1, 0, JtJ.bottomLeftCorner<6, 6>());
  EXPECT_EQ(relative_only.Compute().code(), StatusCode::kFailedPrecondition);

  // A position fix alone leaves the rotation free.
  MarginalCovariance position_only(1);
  Matrix6d info = Matrix6d::Zero();
  info.topLeftCorner<3, 3>().setIdentity();
  position_only.Add(0, 0, info);
  EXPECT_EQ(position_only.Compute().code(), StatusCode::kFailedPrecondition);

  // Full rank for contrast: the same with a prior.
  relative_only.Add(0, 0, Matrix6d::Identity());
  EXPECT_TRUE(relative_only.Compute().ok());
}

Matrix6d Information(double sigma_t, double sigma_r) {
  Vector6d d;
  d << sigma_t, sigma_t, sigma_t, sigma_r, sigma_r, sigma_r;
  return d.cwiseAbs2().cwiseInverse().asDiagonal();
}

Pose3 P(double x, double y, double yaw) {
  return {Eigen::Vector3d(x, y, 0.1 * x), so3::ExpQuaternion(Eigen::Vector3d(0.02 * y, 0.0, yaw))};
}

// A small SlamGraph with an own component (prior, frame switches, an inconsistent match under the
// Cauchy loss) and a floating one (its gauge held constant, also with a match): its covariances
// and MarginalCovariance on the same problem must equal ceres::Covariance's.
TEST(MarginalCovarianceTest, MatchesCeresCovarianceOnASlamGraph) {
  SlamGraphOptions options;
  options.cauchy_c = 1.0;
  SlamGraph g(options);
  const Matrix6d info = Information(0.05, 0.01);
  std::vector<uint64_t> keys;
  for (char robot : {'a', 'b'}) {
    for (uint64_t k = 0; k < 4; ++k) keys.push_back(VariableKey(VariableKind::kSubmap, robot, k));
  }
  auto factor = [&](FactorKind kind, uint64_t a, uint64_t b, const Pose3& z) {
    ASSERT_TRUE(g.AddFactor(SlamFactor{.kind = kind, .a = a, .b = b, .z = z, .information = info}).ok());
  };
  factor(FactorKind::kPrior, keys[0], 0, P(0, 0, 0));
  for (int r = 0; r < 2; ++r) {
    for (size_t k = 0; k < 3; ++k) {
      factor(FactorKind::kFrameSwitch, keys[4 * r + k], keys[4 * r + k + 1], P(1.0, 0.1 * r, 0.2));
    }
    // Off by 0.3 m and 0.05 rad: the loss's weight and curvature correction matter.
    factor(FactorKind::kMatch, keys[4 * r], keys[4 * r + 3], P(3.3, 0.5, 0.65));
  }
  g.SolveFull();
  ASSERT_EQ(g.Unconnected().size(), 4u);
  auto cov = g.Covariances(keys);
  ASSERT_TRUE(cov.ok()) << cov.status().message();

  // The same problem rebuilt at the graph's estimate; the floating component's gauge is its first
  // variable.
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  const auto manifold = MakePoseManifold();
  ceres::CauchyLoss cauchy(options.cauchy_c);
  std::map<uint64_t, std::array<double, 7>> blocks;
  for (uint64_t key : keys) PoseToBlock(*g.Pose(key), blocks[key].data());
  for (const SlamFactor& f : g.factors()) {
    ceres::LossFunction* loss = IsRobustFactor(f.kind) ? &cauchy : nullptr;
    if (IsUnary(f.kind)) {
      problem.AddResidualBlock(AbsolutePoseResidual::Create(f.z, f.information), loss, blocks[f.a].data());
    } else {
      problem.AddResidualBlock(RelativePoseResidual::Create(f.z, f.information), loss, blocks[f.a].data(),
                               blocks[f.b].data());
    }
  }
  for (auto& [key, block] : blocks) problem.SetManifold(block.data(), manifold.get());
  problem.SetParameterBlockConstant(blocks[keys[4]].data());

  ceres::Covariance::Options co;
  co.algorithm_type = ceres::DENSE_SVD;
  ceres::Covariance reference(co);
  std::vector<std::pair<const double*, const double*>> pairs;
  for (uint64_t key : keys) pairs.emplace_back(blocks[key].data(), blocks[key].data());
  ASSERT_TRUE(reference.Compute(pairs, &problem));

  auto mc = MarginalCovariance::FromProblem(problem);
  ASSERT_TRUE(mc.ok()) << mc.status().message();
  ASSERT_TRUE(mc->Compute().ok());
  EXPECT_EQ(mc->num_blocks(), 7);
  EXPECT_EQ(mc->IndexOf(blocks[keys[4]].data()), -1);  // the gauge has no column
  for (size_t i = 0; i < keys.size(); ++i) {
    Eigen::Matrix<double, 6, 6, Eigen::RowMajor> row_major;
    reference.GetCovarianceBlockInTangentSpace(blocks[keys[i]].data(), blocks[keys[i]].data(), row_major.data());
    const Matrix6d ref = row_major;
    if (keys[i] == keys[4]) {
      EXPECT_EQ(ref.norm(), 0.0);
      EXPECT_EQ((*cov)[i].norm(), 0.0);
      continue;
    }
    const Matrix6d mine = mc->Marginal(mc->IndexOf(blocks[keys[i]].data()));
    EXPECT_LT((mine - ref).norm(), 1e-9 * ref.norm()) << i;
    // SlamGraph reports the rotation in radians, twice Ceres' quaternion tangent.
    Matrix6d radians = ref;
    radians.bottomRows<3>() *= 2.0;
    radians.rightCols<3>() *= 2.0;
    EXPECT_LT(((*cov)[i] - radians).norm(), 1e-9 * radians.norm()) << i;
  }
  // The loss is active: without it the match would weigh more and shrink the covariance.
  ceres::Problem::EvaluateOptions eo;
  double cost_with_loss = 0.0, cost_without = 0.0;
  problem.Evaluate(eo, &cost_with_loss, nullptr, nullptr, nullptr);
  eo.apply_loss_function = false;
  problem.Evaluate(eo, &cost_without, nullptr, nullptr, nullptr);
  EXPECT_LT(cost_with_loss, 0.9 * cost_without);
}

TEST(MarginalCovarianceTest, RejectsAProblemWithoutGauge) {
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  const auto manifold = MakePoseManifold();
  std::array<double, 7> a{}, b{};
  PoseToBlock(P(0, 0, 0), a.data());
  PoseToBlock(P(1, 0, 0.1), b.data());
  problem.AddResidualBlock(RelativePoseResidual::Create(P(1, 0, 0.1), Information(0.1, 0.01)), nullptr, a.data(),
                           b.data());
  problem.SetManifold(a.data(), manifold.get());
  problem.SetManifold(b.data(), manifold.get());
  auto mc = MarginalCovariance::FromProblem(problem);
  ASSERT_TRUE(mc.ok());
  EXPECT_EQ(mc->Compute().code(), StatusCode::kFailedPrecondition);

  // All blocks constant: nothing to invert, no block has a covariance of its own.
  problem.SetParameterBlockConstant(a.data());
  problem.SetParameterBlockConstant(b.data());
  auto fixed = MarginalCovariance::FromProblem(problem);
  ASSERT_TRUE(fixed.ok());
  EXPECT_TRUE(fixed->Compute().ok());
  EXPECT_EQ(fixed->IndexOf(a.data()), -1);
}

}  // namespace
}  // namespace cairn
