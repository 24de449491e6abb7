#include "estimation/slam_graph.h"

#include <algorithm>
#include <random>

#include <gtest/gtest.h>

#include "estimation/pose_factors.h"
#include "estimation/so3.h"
#include "estimation/topology_builder.h"

namespace cairn {
namespace {

Pose3 P(double x, double y, double z, double yaw, double roll = 0.0) {
  return {Eigen::Vector3d(x, y, z), so3::ExpQuaternion(Eigen::Vector3d(roll, 0.0, yaw))};
}

Matrix6d Cov(double sigma_t, double sigma_r) {
  Vector6d d;
  d << sigma_t, sigma_t, sigma_t, sigma_r, sigma_r, sigma_r;
  return d.cwiseAbs2().asDiagonal();
}

// Two robots driving known trajectories; each keeps submaps every 4 poses. Produces the factors of
// either topology plus a detection (robot b seen from robot a) and a later submap match.
struct Scenario {
  std::vector<SlamFactor> factors;
  std::vector<std::pair<uint64_t, Pose3>> truth;  // variable -> true world pose
  uint64_t detection_index = 0;                    // position of the first inter-robot factor
};

Scenario MakeScenario(TopologyBuilder::Topology topology, double noise, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> n(0.0, 1.0);
  auto perturb = [&](const Pose3& p, double s) {
    return p * Pose3{s * Eigen::Vector3d(n(rng), n(rng), n(rng)),
                     so3::ExpQuaternion(0.1 * s * Eigen::Vector3d(n(rng), n(rng), n(rng)))};
  };
  Scenario sc;
  const Pose3 start[2] = {P(0, 0, 0, 0), P(3, -2, 0.5, 1.0, 0.05)};
  std::vector<uint64_t> submaps[2];
  std::vector<Pose3> submap_truth[2];
  uint64_t x_key[2][12] = {};
  Pose3 x_truth[2][12];
  for (int r = 0; r < 2; ++r) {
    TopologyBuilder b(topology, static_cast<char>('a' + r));
    for (auto& f : b.Start(r == 0, Matrix6d::Identity() * 1e6)) sc.factors.push_back(f);
    Pose3 origin = start[r];
    submaps[r].push_back(b.SubmapKey(0));
    submap_truth[r].push_back(origin);
    for (int k = 0; k < 12; ++k) {
      const Pose3 x = start[r] * P(0.5 * k, 0.2 * k * (r ? -1 : 1), 0.01 * k, 0.15 * k);
      if (k > 0 && k % 4 == 0) {  // frame switch at the current pose, gravity-aligned origin
        const Pose3 new_origin = x;
        for (auto& f : b.FrameSwitch(perturb(origin.Inverse() * new_origin, noise), Cov(0.05, 0.01))) {
          sc.factors.push_back(f);
        }
        origin = new_origin;
        submaps[r].push_back(b.SubmapKey(b.current_submap()));
        submap_truth[r].push_back(origin);
      }
      uint64_t key = 0;
      for (auto& f : b.PoseEstimate(perturb(origin.Inverse() * x, noise), Cov(0.02 * (k % 4 + 1), 0.005), &key)) {
        sc.factors.push_back(f);
      }
      x_key[r][k] = key;
      x_truth[r][k] = x;
      sc.truth.emplace_back(key, x);
    }
    for (size_t i = 0; i < submaps[r].size(); ++i) sc.truth.emplace_back(submaps[r][i], submap_truth[r][i]);
  }
  sc.detection_index = sc.factors.size();
  SlamFactor d;  // eq. 4.7 already applied: pose of robot b in robot a at the same time
  d.kind = FactorKind::kDetection;
  d.a = x_key[0][5];
  d.b = x_key[1][5];
  d.z = perturb(x_truth[0][5].Inverse() * x_truth[1][5], noise);
  d.information = Cov(0.05, 0.02).inverse();
  sc.factors.push_back(d);
  SlamFactor c;
  c.kind = FactorKind::kMatch;
  c.a = submaps[0][2];
  c.b = submaps[1][1];
  c.z = perturb(submap_truth[0][2].Inverse() * submap_truth[1][1], noise);
  c.information = Cov(0.03, 0.01).inverse();
  sc.factors.push_back(c);
  return sc;
}

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
    const Matrix6d ref = C.block<6, 6>(column[keys[i]], column[keys[i]]);
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
