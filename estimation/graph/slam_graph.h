#pragma once
// The online multi-robot SLAM graph of thesis 4.2: robot poses x, submap origins s and landmarks l
// (6-D each, tagged with their robot), connected by the prior on the own robot's first submap,
// frame switches w (s_i -> s_i+1), filter estimates v (s_j -> x), sequential odometry u (x -> x,
// the alternative topology of Fig. 4.2a, see TopologyBuilder), robot detections d (x -> x, eq. 4.7),
// landmark observations o (x -> l), submap matches c (s -> s) and absolute pose / position fixes.
//
// Online use: AddFactor() as measurements arrive, in any order (a factor between unknown variables
// starts a floating component; a position fix on an unknown variable waits for it), then Update().
// An update re-optimizes only a window around the new factors (the variables within a few factor
// hops; the rest held fixed), bounded in iterations and time, so its cost does not grow with the
// graph. Factors that do not fit the estimate (a loop closure) also start a full solve of a snapshot
// of the graph, re-initialized chordally for large ones; with a background runner it runs on
// another thread and the next Update() after it finishes merges it: variables added meanwhile
// follow the correction of the variable they were created from, and the window around the newer
// factors is re-optimized. Without a runner the full solve runs inside Update() (deterministic).
//
// Components not connected to the own robot's prior float with their first variable as gauge and
// are reported by Unconnected(); an inter-component factor moves the floating part rigidly onto
// the measurement and joins it.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "common/options_visitor.h"
#include "common/status.h"
#include "estimation/graph/pose_graph.h"
#include "estimation/graph/slam_graph_types.h"

namespace ceres {
class Problem;
class LossFunction;
class Manifold;
namespace internal {
class ResidualBlock;
}  // namespace internal
using ResidualBlockId = internal::ResidualBlock*;
}  // namespace ceres

namespace cairn {

class GraphBatchJob;
struct GraphSnapshot;

struct SlamGraphOptions {
  char own_robot = 'a';
  double cauchy_c = 3.0;                 // eq. 4.10 on d, o, c and fixes; 0 disables
  int64_t update_iterations = 10;        // bounded incremental update
  // Update() skips the solve while the factors added since the last one fit the current estimate
  // within this cost (e.g. odometry extending a chain): nothing to re-optimize.
  double update_min_cost = 1e-9;
  // The update window: variables within this many factor hops of the new factors' variables, at
  // most `window_variables` of them (nearest first).
  int64_t window_hops = 2;
  int64_t window_variables = 48;
  double window_tolerance = 1e-6;  // relative cost change that ends a window solve
  // New factors whose cost (at insertion) exceeds this need more than the window: a full solve of
  // the graph is started; 0 = after every update that solved.
  double full_solve_cost = 1.0;
  // A large loop closure (new factors' cost above this) re-initializes the graph chordally
  // (rotation-first, escapes the local minima an incremental warm start runs into) before the
  // full solve; 0 disables.
  double reinitialize_cost = 50.0;
  double update_seconds = 0.01;
  int64_t full_iterations = 100;
  // Covariances are recomputed when a requested origin moved more than this since last time, or
  // factors were added.
  double covariance_translation_change = 0.01;  // m
  double covariance_rotation_change = 0.002;    // rad

  void Visit(OptionsVisitor& v) {
    std::string robot(1, own_robot);
    v.Text("own_robot", robot);
    if (!robot.empty()) own_robot = robot[0];
    v.Number("cauchy_c", cauchy_c, 0.0, 1e6, "sqrt(chi2)");
    v.Integer("update_iterations", update_iterations, 1, 1000, "iterations");
    v.Number("update_min_cost", update_min_cost, 0.0, 1e6, "chi2/2");
    v.Integer("window_hops", window_hops, 1, 1000, "factors");
    v.Integer("window_variables", window_variables, 2, 1000000, "variables");
    v.Number("window_tolerance", window_tolerance, 1e-16, 0.1, "relative");
    v.Number("full_solve_cost", full_solve_cost, 0.0, 1e12, "chi2/2");
    v.Number("reinitialize_cost", reinitialize_cost, 0.0, 1e12, "chi2/2");
    v.Number("update_seconds", update_seconds, 1e-4, 10.0, "s");
    v.Integer("full_iterations", full_iterations, 1, 100000, "iterations");
    v.Number("covariance_translation_change", covariance_translation_change, 0.0, 100.0, "m");
    v.Number("covariance_rotation_change", covariance_rotation_change, 0.0, 3.2, "rad");
  }
};

struct SlamUpdateStats {
  bool solved = false;  // false when nothing needed re-optimizing
  bool reinitialized = false;     // a full solve with chordal re-initialization was merged
  bool full_solve_merged = false; // a (background or inline) full solve's result was merged
  bool full_solve_started = false;
  int iterations = 0;             // of the window solve (and an inline full solve)
  int window_variables = 0;
  double seconds = 0.0;
  double cost = 0.0;  // Ceres cost of the last solve (1/2 sum of robustified squared residuals)
};

class SlamGraph {
 public:
  // Runs a task on another thread (e.g. a low-priority executor); must not run it inline.
  using BackgroundRunner = std::function<void(std::function<void()>)>;

  explicit SlamGraph(const SlamGraphOptions& options = {});
  ~SlamGraph();
  SlamGraph(const SlamGraph&) = delete;
  SlamGraph& operator=(const SlamGraph&) = delete;

  // Full solves run through `runner` from now on; an empty runner makes them inline again.
  void SetBackgroundRunner(BackgroundRunner runner) { runner_ = std::move(runner); }

  // Adds a factor; returns an error for malformed factors (wrong kinds, non-PD information).
  Status AddFactor(const SlamFactor& factor);
  // Bounded incremental optimization (warm-started window; merges / starts full solves).
  SlamUpdateStats Update();
  // Waits for a running full solve, merges it, and optimizes the whole graph to convergence.
  SlamUpdateStats SolveFull();
  // The last solve of a mission: SolveFull() from the current estimate, and again from a chordal
  // re-initialization; the lower cost is kept (the chordal one on a tie). Robots holding the same
  // factors have different warm starts (their own incremental histories), and with robust losses
  // those can settle in different minima; the chordal start is the same for every robot.
  SlamUpdateStats SolveFinal();
  // Waits for a running full solve and merges it (no further optimization).
  void WaitForBackground();
  // Waits and updates until no full solve runs (a merged one may start another for the factors
  // that arrived while it ran), at most `max_rounds` times; returns the re-initializations merged.
  int Settle(int max_rounds = 10);
  bool background_running() const { return job_ != nullptr; }
  int full_solves() const { return full_solves_; }
  int stale_full_solves() const { return stale_full_solves_; }
  // Chordal re-initialization of all variables from the binary factors (anchors: the variables of
  // the prior and the floating components' gauges keep their poses).
  Status ReinitializeChordal();

  bool HasVariable(uint64_t key) const { return variables_.count(key) != 0; }
  Expected<Pose3> Pose(uint64_t key) const;
  // Eq. 4.6: latest submap origin of `robot` composed with the filter's estimate in it.
  Expected<Pose3> GlobalPose(char robot, const Pose3& T_s_x) const;
  // Variables not connected to the own robot's prior.
  std::vector<uint64_t> Unconnected() const;
  // Whether `key` is a variable connected to the own robot's prior.
  bool Tied(uint64_t key) const;
  // Moves the floating component holding `key` rigidly by `correction` (left-multiplied) and makes
  // it part of the own robot's, for a placement found outside the graph (GNSS fixes of a robot
  // never matched or seen); factors added next must tie it. Error when `key` is unknown or tied.
  Status PlaceComponent(uint64_t key, const Pose3& correction);
  // Factors waiting for a variable to become reachable.
  size_t pending_factors() const { return pending_.size(); }
  size_t num_factors() const { return num_added_factors_; }
  size_t num_variables() const { return variables_.size(); }
  // Marginal covariances (tangent space [t, rotation], rotation perturbation on the left) of the
  // given variables; cached until the graph changes significantly.
  Expected<std::vector<Matrix6d>> Covariances(const std::vector<uint64_t>& keys);
  int covariance_computations() const { return covariance_computations_; }
  // Sum over factors of the squared whitened residual (no loss, no 1/2).
  double Chi2() const;
  // One factor's share of Chi2(); its variables must be in the graph.
  double FactorChi2(const SlamFactor& f) const;
  // The factors in the graph (not the pending ones), in insertion order, and the variables' keys.
  const std::vector<SlamFactor>& factors() const { return factors_; }
  std::vector<uint64_t> VariableKeys() const;

 private:
  struct Variable {
    std::unique_ptr<double[]> block;  // tx ty tz qx qy qz qw
    int component = 0;
    bool gauge = false;               // held constant as the anchor of a floating component
    uint64_t parent = 0;              // the variable it was placed from (itself for anchors)
    std::vector<uint32_t> factors;    // indices into factors_
  };
  void Insert(const SlamFactor& f);
  Variable& CreateVariable(uint64_t key, const Pose3& initial, int component, uint64_t parent);
  // Moves component `drop` rigidly by `correction` (left-multiplied) and merges it into `keep`.
  void JoinComponents(int keep, int drop, const Pose3& correction);
  // Places unknown or floating variable `key` at `pose` in the world (own component).
  void AnchorToWorld(uint64_t key, const Pose3& pose);
  SlamUpdateStats Solve(int iterations, double seconds);
  // Window solve around `seeds`.
  SlamUpdateStats SolveWindow(const std::vector<uint64_t>& seeds);
  std::vector<uint64_t> WindowAround(const std::vector<uint64_t>& seeds) const;
  GraphSnapshot Snapshot() const;
  ceres::Manifold* ManifoldOf(uint64_t key) const;
  // Writes the snapshot's poses back into the variables of the same keys.
  void SetPoses(const GraphSnapshot& snapshot);
  void StartFullSolve(bool chordal);
  // Merges a finished full solve; returns false (and drops it) when the graph's structure changed.
  bool MergeFullSolve();
  // Waits for the running full solve and merges it; returns whether it was merged (not stale).
  bool MergeRunningJob();

  SlamGraphOptions options_;
  std::unique_ptr<ceres::Problem> problem_;
  std::unique_ptr<ceres::Manifold> manifold_;
  std::unique_ptr<ceres::Manifold> plane_manifold_;
  std::unique_ptr<ceres::Manifold> line_manifold_;
  std::unique_ptr<ceres::LossFunction> cauchy_;
  std::map<uint64_t, Variable> variables_;
  std::vector<uint64_t> creation_order_;
  std::map<int, std::set<uint64_t>> components_;   // component id -> members
  int own_component_ = -1;                         // component holding the prior
  int next_component_ = 0;
  std::vector<SlamFactor> pending_;
  std::vector<SlamFactor> factors_;                // inserted ones, for Chi2()
  std::vector<ceres::ResidualBlockId> residual_ids_;  // parallel to factors_
  size_t num_added_factors_ = 0;
  double new_cost_ = 0.0;  // cost of the factors added since the last solve, at insertion
  size_t solved_factors_ = 0;          // factors_[solved_factors_..] are new since the last update
  std::vector<uint64_t> unconverged_;  // the last window stopped early: the next Update() resumes it
  // Full solves.
  BackgroundRunner runner_;
  std::shared_ptr<GraphBatchJob> job_;
  size_t job_factors_ = 0;          // factors_ in the running job's snapshot
  size_t job_variables_ = 0;        // creation_order_ entries in it
  bool full_solve_wanted_ = false;  // another full solve after the running one
  bool chordal_wanted_ = false;
  uint64_t structure_version_ = 0;  // bumped by joins, component shifts and re-initializations
  int full_solves_ = 0;
  int stale_full_solves_ = 0;
  std::map<char, uint64_t> latest_submap_;
  // Covariance cache.
  std::map<uint64_t, std::pair<Pose3, Matrix6d>> covariance_cache_;
  size_t covariance_factor_count_ = 0;
  int covariance_computations_ = 0;
};

}  // namespace cairn
