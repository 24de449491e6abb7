#include <algorithm>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/pipeline/submap_matching_stage.h"
#include "daemon/pipeline/testing/loop_mission.h"

// The matcher pool on its worker threads (also run under ThreadSanitizer).
namespace cairn {
namespace {

TEST(SubmapMatchingStageTest, APoolOfWorkersGivesTheSameMatchesAsInline) {
  const testing::LoopMission m = testing::MakeLoop(5);
  GraphStageOptions go;
  go.enabled = true;
  SubmapMatchingOptions mo;
  mo.enabled = true;
  mo.workers = 2;
  auto run = [&](bool deterministic) {
    GraphStage graph(go, /*deterministic=*/true);
    SubmapMatchingStage stage(mo, "rover", deterministic, ExecutorOptions{}, nullptr);
    stage.Start();
    for (const GraphInput& in : m.inputs) graph.OnInput(in);
    for (const auto& s : m.submaps) stage.OnSubmap(s);
    stage.Drain(graph);
    std::vector<std::pair<uint64_t, uint64_t>> matched;
    for (const MatchAttempt& a : stage.attempts()) {
      if (a.result.matched()) matched.emplace_back(a.a.id, a.b.id);
    }
    std::sort(matched.begin(), matched.end());
    return matched;
  };
  const auto inline_matches = run(true);
  EXPECT_FALSE(inline_matches.empty());
  EXPECT_EQ(run(false), inline_matches);
}

}  // namespace
}  // namespace cairn
