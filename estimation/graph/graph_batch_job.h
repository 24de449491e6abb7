#pragma once
// A full solve of a snapshot of the SLAM graph, runnable on any thread (thesis 4.2: large loop
// closures are absorbed by a fuller solve that must not block the online updates). The job owns
// copies of the factors and poses, so the live graph keeps changing while it runs; SlamGraph
// merges the result back when the job is done.

#include <atomic>
#include <cstdint>
#include <vector>

#include "common/status.h"
#include "estimation/graph/pose_graph.h"
#include "estimation/graph/slam_graph_types.h"

namespace ceres {
class Problem;
}  // namespace ceres

namespace cairn {

struct GraphSnapshot {
  std::vector<SlamFactor> factors;
  std::vector<uint64_t> keys;     // ascending
  std::vector<Pose3> poses;       // of keys
  std::vector<uint8_t> constant;  // gauges of floating components, held fixed
};

struct GraphSolveResult {
  int iterations = 0;
  double cost = 0.0;  // Ceres cost (1/2 sum of robustified squared residuals)
  bool converged = false;
};

// The solver settings every graph solve uses (Levenberg-Marquardt, sparse Cholesky, one thread,
// silent).
GraphSolveResult SolveGraphProblem(ceres::Problem& problem, int iterations, double seconds,
                                   double function_tolerance = 1e-10);

// Chordal (rotation-first) re-initialization of the snapshot's poses from its binary factors;
// anchors (the variables of the prior / absolute poses and the gauges) keep their poses.
Status InitializeSnapshotChordal(GraphSnapshot& snapshot);

class GraphBatchJob {
 public:
  GraphBatchJob(GraphSnapshot snapshot, bool chordal, double cauchy_c, int64_t iterations, uint64_t version);

  // Solves to convergence; call once, from any thread.
  void Run();
  bool Done() const { return done_.load(std::memory_order_acquire); }
  // Blocks until Run() has finished on whichever thread runs it.
  void Wait() const { done_.wait(false, std::memory_order_acquire); }

  // After Done():
  const GraphSnapshot& result() const { return snapshot_; }
  const GraphSolveResult& stats() const { return stats_; }
  bool reinitialized() const { return reinitialized_; }
  double seconds() const { return seconds_; }
  // SlamGraph's structure version when the snapshot was taken: a join of components or a shift of
  // a floating one since then makes the result stale.
  uint64_t version() const { return version_; }

 private:
  GraphSnapshot snapshot_;
  bool chordal_;
  double cauchy_c_;
  int64_t iterations_;
  uint64_t version_;
  GraphSolveResult stats_;
  bool reinitialized_ = false;
  double seconds_ = 0.0;
  std::atomic<bool> done_{false};
};

}  // namespace cairn
