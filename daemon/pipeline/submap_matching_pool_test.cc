#include <set>
#include <utility>

#include <gtest/gtest.h>

#include "daemon/pipeline/submap_matching_stage.h"
#include "daemon/pipeline/testing/loop_mission.h"

// The matcher pool on its worker threads (also run under ThreadSanitizer). Which pairs a pool
// attempts depends on when results come back (each result moves the graph, and with it the
// pairing), so the test checks what must hold in any order, not one order's list.
namespace cairn {
namespace {

TEST(SubmapMatchingPoolTest, WorkersCloseTheLoopWithCorrectMatchesOnly) {
  const testing::LoopMission m = testing::MakeLoop(5);
  GraphStageOptions go;
  go.enabled = true;
  GraphStage graph(go, /*deterministic=*/true);
  GraphStage odometry_only(go, /*deterministic=*/true);
  SubmapMatchingOptions mo;
  mo.enabled = true;
  mo.workers = 2;
  mo.queue = 2;
  SubmapMatchingStage stage(mo, "rover", /*deterministic=*/false, ExecutorOptions{}, nullptr);
  stage.Start();
  for (const GraphInput& in : m.inputs) {
    graph.OnInput(in);
    odometry_only.OnInput(in);
  }
  for (const auto& s : m.submaps) {
    stage.OnSubmap(s);
    stage.Step(graph);  // hands out pairs while other jobs still run
  }
  stage.Drain(graph);
  graph.Finish();
  odometry_only.Finish();

  const SubmapMatchingReport r = stage.report();
  EXPECT_EQ(r.submaps, 5u);
  EXPECT_EQ(r.suitable, 5u);
  EXPECT_GE(r.accepted, 2u);
  std::set<std::pair<uint64_t, uint64_t>> seen;
  for (const MatchAttempt& a : stage.attempts()) {
    EXPECT_TRUE(seen.emplace(a.a.id, a.b.id).second) << "attempted twice: " << a.a.id << "-" << a.b.id;
    if (!a.result.matched()) continue;
    const Eigen::Isometry3d truth = m.T_world_origin[a.a.id].inverse() * m.T_world_origin[a.b.id];
    EXPECT_LT((a.result.T_a_b.translation() - truth.translation()).norm(), 0.05) << a.a.id << "-" << a.b.id;
  }
  EXPECT_EQ(graph.report().matches, r.accepted);
  EXPECT_LT(testing::OriginError(graph, m), 0.5 * testing::OriginError(odometry_only, m));
}

}  // namespace
}  // namespace cairn
