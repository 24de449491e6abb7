#include "estimation/graph/graph_replay.h"

#include <algorithm>
#include <chrono>

#include "estimation/graph/pose_graph_solver.h"

namespace cairn {
namespace {

char RobotOfG2oId(uint64_t id) {
  const unsigned r = RobotOfKey(id);
  return r == 0 ? 'a' : static_cast<char>(r);
}

}  // namespace

uint64_t SubmapKeyOfG2oId(uint64_t id) {
  return VariableKey(VariableKind::kSubmap, RobotOfG2oId(id), IndexOfKey(id));
}

Expected<GraphReplayResult> ReplayPoseGraph(PoseGraph& g, SlamGraphOptions options,
                                            SlamGraph::BackgroundRunner runner) {
  if (g.num_vertices() == 0) return InvalidArgumentError("replay: empty graph");
  std::vector<size_t> order(g.num_vertices());
  for (size_t i = 0; i < order.size(); ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](size_t x, size_t y) { return g.ids()[x] < g.ids()[y]; });
  std::vector<size_t> rank(g.num_vertices());
  for (size_t r = 0; r < order.size(); ++r) rank[order[r]] = r;
  std::vector<std::vector<size_t>> edges_at(g.num_vertices());
  for (size_t k = 0; k < g.edges().size(); ++k) {
    const auto& e = g.edges()[k];
    edges_at[std::max(rank[g.Find(e.from)], rank[g.Find(e.to)])].push_back(k);
  }
  options.own_robot = RobotOfG2oId(g.ids()[order[0]]);
  SlamGraph slam(options);
  slam.SetBackgroundRunner(std::move(runner));
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = SubmapKeyOfG2oId(g.ids()[order[0]]);
  prior.z = g.poses()[order[0]];
  prior.information = Matrix6d::Identity() * 1e8;
  CAIRN_RETURN_IF_ERROR(slam.AddFactor(prior));
  GraphReplayResult result;
  for (size_t r = 0; r < order.size(); ++r) {
    if (edges_at[r].empty()) continue;
    const auto t0 = std::chrono::steady_clock::now();
    for (size_t k : edges_at[r]) {
      const auto& e = g.edges()[k];
      SlamFactor f;
      f.kind = IsLoopClosure(e) ? FactorKind::kMatch : FactorKind::kFrameSwitch;
      f.a = SubmapKeyOfG2oId(e.from);
      f.b = SubmapKeyOfG2oId(e.to);
      f.z = e.T_from_to;
      f.information = e.information;
      const Status s = slam.AddFactor(f);
      if (!s.ok()) return s.WithContext("edge " + std::to_string(k));
    }
    result.reinitializations += slam.Update().reinitialized ? 1 : 0;
    result.step_seconds.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
  }
  const auto settle = std::chrono::steady_clock::now();
  result.reinitializations += slam.Settle();
  result.settle_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - settle).count();
  result.full_solves = slam.full_solves();
  result.stale_full_solves = slam.stale_full_solves();
  for (size_t i = 0; i < g.num_vertices(); ++i) {
    auto p = slam.Pose(SubmapKeyOfG2oId(g.ids()[i]));
    if (p.ok()) g.poses()[i] = *p;
  }
  result.unconnected = slam.Unconnected().size();
  return result;
}

}  // namespace cairn
