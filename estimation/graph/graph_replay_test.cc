#include "estimation/graph/graph_replay.h"

#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "estimation/graph/g2o_io.h"
#include "estimation/graph/pose_graph_solver.h"

namespace cairn {
namespace {

// Online replay of a crop of a real graph ends at the batch optimum (1 %).
TEST(GraphReplayTest, OnlineReplayEndsAtTheBatchOptimum) {
  const char* dir = std::getenv("CAIRN_DATA_DIR");
  const std::string path = std::string(dir ? dir : "") + "/posegraphs/intel.g2o";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto full = ReadG2o(path);
  ASSERT_TRUE(full.ok());
  PoseGraph crop;
  for (size_t i = 0; i < full->num_vertices(); ++i) {
    if (full->ids()[i] < 250) crop.SetVertex(full->ids()[i], full->poses()[i]);
  }
  for (const auto& e : full->edges()) {
    if (e.from < 250 && e.to < 250) crop.AddEdge(e);
  }
  crop.set_has_initial_estimate(true);
  PoseGraph batch = crop;
  ASSERT_TRUE(SolvePoseGraph(batch, PoseGraphSolverOptions()).ok());
  SlamGraphOptions o;
  o.cauchy_c = 0.0;
  o.update_seconds = 10.0;  // bounded by iterations only: deterministic under sanitizers
  auto replay = ReplayPoseGraph(crop, o);
  ASSERT_TRUE(replay.ok()) << replay.status().message();
  EXPECT_EQ(replay->unconnected, 0u);
  EXPECT_GT(replay->step_seconds.size(), 200u);
  EXPECT_LT(GeodesicChi2(crop), 1.01 * GeodesicChi2(batch));
}

}  // namespace
}  // namespace cairn
