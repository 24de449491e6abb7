#include "estimation/graph/slam_graph.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "estimation/graph/pose_factors.h"
#include "estimation/graph/topology_builder.h"
#include "estimation/math/so3.h"
#include "estimation/testing/slam_graph_scenario.h"

namespace cairn {
namespace {

using namespace testing_scenario;


TEST(SlamGraphTest, TwoRobotsWithoutNoiseAreRecoveredExactlyInBothTopologies) {
  for (auto topology : {TopologyBuilder::Topology::kFilter, TopologyBuilder::Topology::kSequential}) {
    const Scenario sc = MakeScenario(topology, 0.0, 1);
    SlamGraph g;
    for (size_t i = 0; i < sc.factors.size(); ++i) {
      if (i == sc.detection_index) {
        // Robot b floats until the detection arrives.
        const auto floating = g.Unconnected();
        EXPECT_FALSE(floating.empty());
        for (uint64_t key : floating) EXPECT_EQ(RobotOfVariable(key), 'b');
      }
      ASSERT_TRUE(g.AddFactor(sc.factors[i]).ok());
      g.Update();
    }
    EXPECT_TRUE(g.Unconnected().empty());
    g.SolveFull();
    for (const auto& [key, truth] : sc.truth) {
      const Pose3 est = *g.Pose(key);
      EXPECT_LT((est.t - truth.t).norm(), 1e-6) << key;
      EXPECT_LT(est.q.angularDistance(truth.q), 1e-6) << key;
    }
    EXPECT_LT(g.Chi2(), 1e-12);
  }
}

TEST(SlamGraphTest, LateAndOutOfOrderFactorsReachTheSameOptimum) {
  const Scenario sc = MakeScenario(TopologyBuilder::Topology::kFilter, 0.02, 2);
  SlamGraph in_order, shuffled;
  for (const auto& f : sc.factors) ASSERT_TRUE(in_order.AddFactor(f).ok());
  in_order.SolveFull();
  std::vector<SlamFactor> late = sc.factors;
  std::mt19937 rng(9);
  std::shuffle(late.begin(), late.end(), rng);
  for (const auto& f : late) {
    ASSERT_TRUE(shuffled.AddFactor(f).ok());
    shuffled.Update();
  }
  EXPECT_TRUE(shuffled.Unconnected().empty());
  shuffled.SolveFull();
  EXPECT_NEAR(in_order.Chi2(), shuffled.Chi2(), 1e-6 * (1 + in_order.Chi2()));
  for (const auto& [key, truth] : sc.truth) {
    EXPECT_LT((in_order.Pose(key)->t - shuffled.Pose(key)->t).norm(), 1e-5) << key;
  }
}

TEST(SlamGraphTest, CauchyLossLimitsAWrongMatch) {
  Scenario sc = MakeScenario(TopologyBuilder::Topology::kFilter, 0.0, 3);
  SlamFactor wrong = sc.factors.back();
  wrong.z = wrong.z * P(4.0, -3.0, 0.0, 1.0);
  sc.factors.push_back(wrong);
  double error[2];
  for (int robust = 0; robust < 2; ++robust) {
    SlamGraphOptions o;
    o.cauchy_c = robust ? 1.0 : 0.0;
    SlamGraph g(o);
    for (const auto& f : sc.factors) ASSERT_TRUE(g.AddFactor(f).ok());
    g.SolveFull();
    error[robust] = 0.0;
    for (const auto& [key, truth] : sc.truth) error[robust] = std::max(error[robust], (g.Pose(key)->t - truth.t).norm());
  }
  EXPECT_GT(error[0], 0.5);
  EXPECT_LT(error[1], 0.1 * error[0]);
}

// Two robots' graphs with the same factors but different histories: one took a wrong match
// before the right detection, and its warm start sits in the wrong match's minimum of the Cauchy
// loss. The final solve also starts from the chordal initialization both compute alike.
TEST(SlamGraphTest, TheFinalSolveGivesGraphsOfTheSameFactorsTheSameMinimum) {
  Scenario sc = MakeScenario(TopologyBuilder::Topology::kFilter, 0.0, 3);
  SlamFactor wrong = sc.factors.back();
  wrong.z = wrong.z * P(4.0, -3.0, 0.0, 2.0);
  SlamGraphOptions o;
  o.cauchy_c = 1.0;
  o.reinitialize_cost = 1e12;  // no chordal start on the way: the histories stay apart
  SlamGraph right_first(o), wrong_first(o);
  for (const auto& f : sc.factors) {
    ASSERT_TRUE(right_first.AddFactor(f).ok());
    right_first.Update();
  }
  ASSERT_TRUE(right_first.AddFactor(wrong).ok());
  right_first.Update();
  for (size_t i = 0; i < sc.factors.size(); ++i) {
    if (i == sc.detection_index) {
      ASSERT_TRUE(wrong_first.AddFactor(wrong).ok());
      wrong_first.Update();
    }
    ASSERT_TRUE(wrong_first.AddFactor(sc.factors[i]).ok());
    wrong_first.Update();
  }
  const auto apart = [&] {
    double d = 0.0;
    for (const auto& [key, truth] : sc.truth) {
      d = std::max(d, (right_first.Pose(key)->t - wrong_first.Pose(key)->t).norm());
    }
    return d;
  };
  right_first.SolveFull();
  wrong_first.SolveFull();
  const double warm_chi2[2] = {right_first.Chi2(), wrong_first.Chi2()};
  EXPECT_GT(apart(), 0.1) << "the warm starts should have settled in different minima";
  const SlamUpdateStats final_stats[2] = {right_first.SolveFinal(), wrong_first.SolveFinal()};
  EXPECT_LT(apart(), 1e-5);
  for (int i = 0; i < 2; ++i) EXPECT_LE(final_stats[i].cost, 0.5 * warm_chi2[i] + 1e-9);
  EXPECT_NEAR(right_first.Chi2(), wrong_first.Chi2(), 1e-6 * (1.0 + right_first.Chi2()));
}

TEST(SlamGraphTest, RejectsFactorsThatDoNotFitTheirVariables) {
  SlamGraph g;
  SlamFactor f;
  f.kind = FactorKind::kFrameSwitch;
  f.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  f.b = VariableKey(VariableKind::kRobotPose, 'a', 0);
  EXPECT_FALSE(g.AddFactor(f).ok());
  f.kind = FactorKind::kDetection;  // same robot
  f.a = VariableKey(VariableKind::kRobotPose, 'a', 0);
  f.b = VariableKey(VariableKind::kRobotPose, 'a', 1);
  EXPECT_FALSE(g.AddFactor(f).ok());
  f.kind = FactorKind::kPrior;  // on another robot
  f.a = VariableKey(VariableKind::kSubmap, 'b', 0);
  EXPECT_FALSE(g.AddFactor(f).ok());
  f.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  f.information = -Matrix6d::Identity();
  EXPECT_FALSE(g.AddFactor(f).ok());
  EXPECT_EQ(g.num_factors(), 0u);
}

TEST(SlamGraphTest, GlobalPoseAndPositionFix) {
  SlamGraph g;
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  SlamFactor fix;  // arrives before its variable exists
  fix.kind = FactorKind::kAbsolutePosition;
  fix.a = VariableKey(VariableKind::kSubmap, 'a', 1);
  fix.position = Eigen::Vector3d(2, 0, 0);
  fix.position_information = Eigen::Matrix3d::Identity() * 100;
  ASSERT_TRUE(g.AddFactor(fix).ok());
  EXPECT_EQ(g.pending_factors(), 1u);
  SlamFactor w;
  w.kind = FactorKind::kFrameSwitch;
  w.a = prior.a;
  w.b = fix.a;
  w.z = P(1, 0, 0, M_PI / 2);
  ASSERT_TRUE(g.AddFactor(prior).ok());
  ASSERT_TRUE(g.AddFactor(w).ok());
  EXPECT_EQ(g.pending_factors(), 0u);
  g.SolveFull();
  // Prior and w are equally sure (unit information), the fix much more: s1 ends near x = 2.
  EXPECT_NEAR(g.Pose(fix.a)->t.x(), 2.0, 0.05);
  const Pose3 global = *g.GlobalPose('a', P(1, 0, 0, 0));
  const Pose3 expected = *g.Pose(fix.a) * P(1, 0, 0, 0);
  EXPECT_LT((global.t - expected.t).norm(), 1e-12);
  EXPECT_NEAR(global.t.y(), g.Pose(fix.a)->t.y() + 1.0, 0.2);  // s1 is turned by 90 degrees
  EXPECT_FALSE(g.GlobalPose('c', Pose3()).ok());
}

// Covariances are in radians for the rotation: a chain of three switches, each 0.01 rad (1 sigma)
// in yaw, leaves the last origin 0.01 * sqrt(3) rad unsure about its yaw.
TEST(SlamGraphTest, CovarianceOfAChainAddsUpInRadians) {
  SlamGraph g;
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  prior.information = Matrix6d::Identity() * 1e12;
  ASSERT_TRUE(g.AddFactor(prior).ok());
  Matrix6d switch_covariance = Matrix6d::Identity() * 1e-2;
  switch_covariance(5, 5) = 1e-4;
  for (uint64_t k = 0; k < 3; ++k) {
    SlamFactor w;
    w.kind = FactorKind::kFrameSwitch;
    w.a = VariableKey(VariableKind::kSubmap, 'a', k);
    w.b = VariableKey(VariableKind::kSubmap, 'a', k + 1);
    w.z = P(1, 0, 0, 0);
    w.information = switch_covariance.inverse();
    ASSERT_TRUE(g.AddFactor(w).ok());
  }
  g.SolveFull();
  auto cov = g.Covariances({VariableKey(VariableKind::kSubmap, 'a', 3)});
  ASSERT_TRUE(cov.ok()) << cov.status().message();
  EXPECT_NEAR((*cov)[0](5, 5), 3e-4, 1e-9);
  EXPECT_NEAR((*cov)[0](0, 0), 3e-2, 1e-8);
}

// Dense reference: H = J^T J from central differences of every whitened residual in the tangent
// space, inverted; the marginal of a variable is its diagonal block.
TEST(SlamGraphTest, CovariancesMatchADenseReference) {
  const Scenario sc = MakeScenario(TopologyBuilder::Topology::kFilter, 0.02, 4);
  SlamGraphOptions o;
  o.cauchy_c = 0.0;  // the reference has no loss
  SlamGraph g(o);
  for (const auto& f : sc.factors) ASSERT_TRUE(g.AddFactor(f).ok());
  g.SolveFull();
  std::vector<uint64_t> keys;
  std::map<uint64_t, int> column;
  for (const auto& [key, truth] : sc.truth) {
    column[key] = 6 * static_cast<int>(keys.size());
    keys.push_back(key);
  }
  const int n = 6 * static_cast<int>(keys.size());
  const auto manifold = MakePoseManifold();
  Eigen::MatrixXd H = Eigen::MatrixXd::Zero(n, n);
  for (const auto& f : sc.factors) {
    std::vector<uint64_t> vars = {f.a};
    if (!IsUnary(f.kind)) vars.push_back(f.b);
    std::unique_ptr<ceres::CostFunction> cost(
        IsUnary(f.kind) ? AbsolutePoseResidual::Create(f.z, f.information)
                        : RelativePoseResidual::Create(f.z, f.information));
    std::vector<std::array<double, 7>> blocks(vars.size());
    std::vector<double*> params;
    for (size_t v = 0; v < vars.size(); ++v) {
      PoseToBlock(*g.Pose(vars[v]), blocks[v].data());
      params.push_back(blocks[v].data());
    }
    Eigen::MatrixXd J = Eigen::MatrixXd::Zero(6, n);
    for (size_t v = 0; v < vars.size(); ++v) {
      const auto x0 = blocks[v];
      for (int k = 0; k < 6; ++k) {
        Vector6d delta = Vector6d::Zero(), rp, rm;
        delta[k] = 1e-6;
        manifold->Plus(x0.data(), delta.data(), blocks[v].data());
        cost->Evaluate(params.data(), rp.data(), nullptr);
        delta[k] = -1e-6;
        manifold->Plus(x0.data(), delta.data(), blocks[v].data());
        cost->Evaluate(params.data(), rm.data(), nullptr);
        blocks[v] = x0;
        J.col(column[vars[v]] + k) = (rp - rm) / 2e-6;
      }
    }
    H += J.transpose() * J;
  }
  const Eigen::MatrixXd C = H.inverse();
  auto cov = g.Covariances(keys);
  ASSERT_TRUE(cov.ok()) << cov.status().message();
  for (size_t i = 0; i < keys.size(); ++i) {
    // The manifold's rotation tangent is half the rotation vector.
    Matrix6d ref = C.block<6, 6>(column[keys[i]], column[keys[i]]);
    ref.bottomRows<3>() *= 2.0;
    ref.rightCols<3>() *= 2.0;
    EXPECT_LT(((*cov)[i] - ref).norm(), 1e-4 * ref.norm()) << keys[i];
  }
  // Cached until the graph changes.
  ASSERT_TRUE(g.Covariances({keys[0]}).ok());
  EXPECT_EQ(g.covariance_computations(), 1);
  ASSERT_TRUE(g.AddFactor(sc.factors.back()).ok());
  ASSERT_TRUE(g.Covariances({keys[0]}).ok());
  EXPECT_EQ(g.covariance_computations(), 2);
}

}  // namespace
}  // namespace cairn
