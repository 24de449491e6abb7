// The online update's window and the full solves: in the background (a runner the test controls,
// or a GraphWorker thread) against inline, merges with factors that arrived meanwhile, stale
// results after a structural change.
#include <functional>
#include <random>

#include <gtest/gtest.h>

#include "estimation/graph/graph_worker.h"
#include "estimation/graph/slam_graph.h"
#include "estimation/testing/slam_graph_scenario.h"

namespace cairn {
namespace {

using namespace testing_scenario;

// Holds the posted task until the test runs it: the full solve "runs" exactly between two chosen
// factors.
struct ManualRunner {
  std::function<void()> task;
  SlamGraph::BackgroundRunner Runner() {
    return [this](std::function<void()> t) { task = std::move(t); };
  }
  bool RunPending() {
    if (!task) return false;
    auto t = std::move(task);
    task = nullptr;
    t();
    return true;
  }
};

double MaxPositionDifference(const SlamGraph& a, const SlamGraph& b) {
  double d = 0.0;
  for (uint64_t key : a.VariableKeys()) d = std::max(d, (a.Pose(key)->t - b.Pose(key)->t).norm());
  return d;
}

TEST(SlamGraphBackgroundTest, FactorsArrivingDuringAFullSolveAreMergedOntoItsResult) {
  const Scenario sc = MakeScenario(TopologyBuilder::Topology::kFilter, 0.02, 3);
  SlamGraph reference;
  for (const auto& f : sc.factors) ASSERT_TRUE(reference.AddFactor(f).ok());
  reference.SolveFull();

  ManualRunner runner;
  SlamGraphOptions o;
  o.update_seconds = 10.0;  // bounded by iterations only: deterministic under sanitizers
  o.full_solve_cost = 0.0;  // every solving update asks for a full solve
  SlamGraph g(o);
  g.SetBackgroundRunner(runner.Runner());
  int started = 0;
  // The full solve started by the match (the last factor but one) runs only after the last
  // factor has arrived; earlier ones run at once.
  for (size_t i = 0; i < sc.factors.size(); ++i) {
    ASSERT_TRUE(g.AddFactor(sc.factors[i]).ok());
    const SlamUpdateStats st = g.Update();
    started += st.full_solve_started ? 1 : 0;
    if (i + 1 < sc.detection_index) runner.RunPending();
  }
  EXPECT_GT(started, 0);
  EXPECT_TRUE(g.background_running());
  ASSERT_TRUE(runner.RunPending());
  for (int round = 0; round < 5 && (g.background_running() || runner.task); ++round) {
    runner.RunPending();
    g.Update();
  }
  EXPECT_FALSE(g.background_running());
  EXPECT_GT(g.full_solves(), 0);
  EXPECT_EQ(g.stale_full_solves(), 0);
  EXPECT_TRUE(g.Unconnected().empty());
  // The merged online estimate is the optimum (the last factors were re-optimized on top of the
  // full solve, which then ran once more).
  EXPECT_LT(MaxPositionDifference(g, reference), 1e-4);
  EXPECT_NEAR(g.Chi2(), reference.Chi2(), 1e-3 * (1.0 + reference.Chi2()));
}

TEST(SlamGraphBackgroundTest, AFullSolveOfAnOutdatedStructureIsDroppedAndRedone) {
  const Scenario sc = MakeScenario(TopologyBuilder::Topology::kFilter, 0.02, 4);
  ManualRunner runner;
  SlamGraphOptions o;
  o.update_seconds = 10.0;
  o.full_solve_cost = 0.0;  // every solving update asks for a full solve
  SlamGraph g(o);
  g.SetBackgroundRunner(runner.Runner());
  for (size_t i = 0; i < sc.detection_index; ++i) {
    ASSERT_TRUE(g.AddFactor(sc.factors[i]).ok());
    g.Update();
    runner.RunPending();
    g.Update();
  }
  ASSERT_FALSE(g.Unconnected().empty());  // robot b floats
  // A solve snapshotted before the detection joins robot b's component is stale after it.
  const Pose3 before = *g.Pose(sc.factors[sc.detection_index].b);
  SlamFactor nudge = sc.factors[sc.detection_index - 1];
  nudge.z.t += Eigen::Vector3d(0.05, 0, 0);
  ASSERT_TRUE(g.AddFactor(nudge).ok());
  EXPECT_TRUE(g.Update().full_solve_started);
  ASSERT_TRUE(g.AddFactor(sc.factors[sc.detection_index]).ok());
  EXPECT_TRUE(g.Unconnected().empty());
  EXPECT_GT((g.Pose(sc.factors[sc.detection_index].b)->t - before.t).norm(), 0.1);  // moved onto a
  ASSERT_TRUE(runner.RunPending());
  const SlamUpdateStats st = g.Update();
  EXPECT_FALSE(st.full_solve_merged);
  EXPECT_EQ(g.stale_full_solves(), 1);
  EXPECT_TRUE(g.background_running());  // redone on the joined graph
  ASSERT_TRUE(runner.RunPending());
  EXPECT_TRUE(g.Update().full_solve_merged);
  EXPECT_EQ(g.stale_full_solves(), 1);
}

TEST(SlamGraphBackgroundTest, AnUpdateMovesOnlyTheWindowAroundTheNewFactor) {
  // A chain of 30 submaps; a match closing the loop 25..29 that contradicts the chain.
  SlamGraphOptions o;
  o.update_seconds = 10.0;
  o.window_hops = 2;
  ManualRunner runner;  // never run: the full solve does not interfere
  SlamGraph g(o);
  g.SetBackgroundRunner(runner.Runner());
  auto key = [](int i) { return VariableKey(VariableKind::kSubmap, 'a', static_cast<uint64_t>(i)); };
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = key(0);
  prior.information = Matrix6d::Identity() * 1e6;
  ASSERT_TRUE(g.AddFactor(prior).ok());
  for (int i = 1; i < 30; ++i) {
    SlamFactor w;
    w.kind = FactorKind::kFrameSwitch;
    w.a = key(i - 1);
    w.b = key(i);
    w.z = P(1.0, 0.0, 0.0, 0.05);
    w.information = Cov(0.05, 0.01).inverse();
    ASSERT_TRUE(g.AddFactor(w).ok());
    EXPECT_FALSE(g.Update().solved);  // extends the chain exactly: nothing to optimize
  }
  std::vector<Pose3> before;
  for (int i = 0; i < 30; ++i) before.push_back(*g.Pose(key(i)));
  SlamFactor c;
  c.kind = FactorKind::kMatch;
  c.a = key(25);
  c.b = key(29);
  c.z = before[25].Inverse() * before[29] * P(0.3, 0.1, 0.0, 0.05);
  c.information = Cov(0.05, 0.01).inverse();
  ASSERT_TRUE(g.AddFactor(c).ok());
  const SlamUpdateStats st = g.Update();
  EXPECT_TRUE(st.solved);
  EXPECT_TRUE(st.full_solve_started);
  EXPECT_EQ(st.window_variables, 7);  // 25 and 29 and everything within two hops: 23..29
  for (int i = 0; i < 30; ++i) {
    const double moved = (g.Pose(key(i))->t - before[static_cast<size_t>(i)].t).norm();
    if (i < 23) {
      EXPECT_EQ(moved, 0.0) << i;  // outside the window: untouched
    } else if (i > 25) {
      EXPECT_GT(moved, 1e-3) << i;  // the loop 25..29 absorbs the match
    }
  }
}

TEST(SlamGraphBackgroundTest, AWorkerThreadReachesTheInlineOptimum) {
  // Both topologies, factors shuffled (late and out of order), full solves on a real thread.
  for (auto topology : {TopologyBuilder::Topology::kFilter, TopologyBuilder::Topology::kSequential}) {
    const Scenario sc = MakeScenario(topology, 0.02, 5);
    std::vector<SlamFactor> late = sc.factors;
    std::mt19937 rng(11);
    std::shuffle(late.begin(), late.end(), rng);
    SlamGraph inline_graph;
    GraphWorker worker;
    SlamGraph background;
    background.SetBackgroundRunner(worker.Runner());
    for (const auto& f : late) {
      ASSERT_TRUE(inline_graph.AddFactor(f).ok());
      inline_graph.Update();
      ASSERT_TRUE(background.AddFactor(f).ok());
      background.Update();
    }
    inline_graph.SolveFull();
    background.SolveFull();
    EXPECT_TRUE(background.Unconnected().empty());
    EXPECT_LT(MaxPositionDifference(background, inline_graph), 1e-5);
    EXPECT_NEAR(background.Chi2(), inline_graph.Chi2(), 1e-6 * (1.0 + inline_graph.Chi2()));
  }
}

}  // namespace
}  // namespace cairn
