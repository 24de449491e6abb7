#pragma once
// The online multi-robot SLAM graph of thesis 4.2: robot poses x, submap origins s and landmarks l
// (6-D each, tagged with their robot), connected by the prior on the own robot's first submap,
// frame switches w (s_i -> s_i+1), filter estimates v (s_j -> x), sequential odometry u (x -> x,
// the alternative topology of Fig. 4.2a, see TopologyBuilder), robot detections d (x -> x, eq. 4.7),
// landmark observations o (x -> l), submap matches c (s -> s) and absolute pose / position fixes.
//
// Online use: AddFactor() as measurements arrive, in any order (a factor between unknown variables
// starts a floating component; a position fix on an unknown variable waits for it), then Update() re-optimizes warm-started within a bounded
// number of iterations and time. Components not connected to the own robot's prior float with
// their first variable as gauge and are reported by Unconnected(); an inter-component factor
// moves the floating part rigidly onto the measurement and joins it.

#include <cstdint>
#include <map>
#include <memory>
#include <set>
#include <vector>

#include "estimation/pose_graph.h"
#include "hal/options_visitor.h"
#include "hal/status.h"

namespace ceres {
class Problem;
class LossFunction;
class Manifold;
}  // namespace ceres

namespace cairn {

enum class VariableKind : uint8_t { kRobotPose = 'x', kSubmap = 's', kLandmark = 'l' };

// Variable key: robot letter in the top byte (as the g2o multi-robot keys), kind in the next.
constexpr uint64_t VariableKey(VariableKind kind, char robot, uint64_t index) {
  return (static_cast<uint64_t>(static_cast<unsigned char>(robot)) << 56) |
         (static_cast<uint64_t>(kind) << 48) | (index & ((uint64_t{1} << 48) - 1));
}
constexpr VariableKind KindOfKey(uint64_t key) { return static_cast<VariableKind>((key >> 48) & 0xff); }
constexpr char RobotOfVariable(uint64_t key) { return static_cast<char>(key >> 56); }
constexpr uint64_t IndexOfVariable(uint64_t key) { return key & ((uint64_t{1} << 48) - 1); }

enum class FactorKind {
  kPrior,             // unary, own robot's first submap
  kFrameSwitch,       // w: s_i -> s_i+1
  kFilterEstimate,    // v: s_j -> x
  kOdometry,          // u: x_i -> x_i+1 (sequential topology)
  kDetection,         // d: x^r0 -> x^r1
  kLandmark,          // o: x -> l
  kMatch,             // c: s -> s
  kAbsolutePose,      // unary pose fix (known landmark, GNSS with heading)
  kAbsolutePosition,  // unary position fix (GNSS)
};

struct SlamFactor {
  FactorKind kind = FactorKind::kPrior;
  uint64_t a = 0;     // first (or only) variable
  uint64_t b = 0;     // second variable of binary factors
  Pose3 z;            // measured pose of b in a (binary), of a in the world (unary pose)
  Matrix6d information = Matrix6d::Identity();  // tx ty tz, rotation vector
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               // kAbsolutePosition
  Eigen::Matrix3d position_information = Eigen::Matrix3d::Identity();
};

bool IsUnary(FactorKind kind);
// Factors that get the Cauchy loss (thesis 4.2.3: detections, landmarks, matches; also fixes).
bool IsRobustFactor(FactorKind kind);

struct SlamGraphOptions {
  char own_robot = 'a';
  double cauchy_c = 3.0;                 // eq. 4.10 on d, o, c and fixes; 0 disables
  int64_t update_iterations = 10;        // bounded incremental update
  // Update() skips the solve while the factors added since the last one fit the current estimate
  // within this cost (e.g. odometry extending a chain): nothing to re-optimize.
  double update_min_cost = 1e-9;
  // A large loop closure (new factors' cost above this) re-initializes the graph chordally
  // (rotation-first, escapes the local minima an incremental warm start runs into) and solves it
  // fully; 0 disables.
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
    v.Number("reinitialize_cost", reinitialize_cost, 0.0, 1e12, "chi2/2");
    v.Number("update_seconds", update_seconds, 1e-4, 10.0, "s");
    v.Integer("full_iterations", full_iterations, 1, 100000, "iterations");
    v.Number("covariance_translation_change", covariance_translation_change, 0.0, 100.0, "m");
    v.Number("covariance_rotation_change", covariance_rotation_change, 0.0, 3.2, "rad");
  }
};

struct SlamUpdateStats {
  bool solved = false;  // false when nothing needed re-optimizing
  bool reinitialized = false;
  int iterations = 0;
  double seconds = 0.0;
  double cost = 0.0;  // Ceres cost (1/2 sum of robustified squared residuals)
};

class SlamGraph {
 public:
  explicit SlamGraph(const SlamGraphOptions& options = {});
  ~SlamGraph();
  SlamGraph(const SlamGraph&) = delete;
  SlamGraph& operator=(const SlamGraph&) = delete;

  // Adds a factor; returns an error for malformed factors (wrong kinds, non-PD information).
  Status AddFactor(const SlamFactor& factor);
  // Bounded incremental optimization (warm start).
  SlamUpdateStats Update();
  // Optimization to convergence.
  SlamUpdateStats SolveFull();
  // Chordal re-initialization of all variables from the binary factors (anchors: the variables of
  // the prior and the floating components' gauges keep their poses).
  Status ReinitializeChordal();

  bool HasVariable(uint64_t key) const { return variables_.count(key) != 0; }
  Expected<Pose3> Pose(uint64_t key) const;
  // Eq. 4.6: latest submap origin of `robot` composed with the filter's estimate in it.
  Expected<Pose3> GlobalPose(char robot, const Pose3& T_s_x) const;
  // Variables not connected to the own robot's prior.
  std::vector<uint64_t> Unconnected() const;
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
  // The factors in the graph (not the pending ones), in insertion order, and the variables' keys.
  const std::vector<SlamFactor>& factors() const { return factors_; }
  std::vector<uint64_t> VariableKeys() const;

 private:
  struct Variable {
    std::unique_ptr<double[]> block;  // tx ty tz qx qy qz qw
    int component = 0;
    bool gauge = false;               // held constant as the anchor of a floating component
  };
  void Insert(const SlamFactor& f);
  Variable& CreateVariable(uint64_t key, const Pose3& initial, int component);
  // Moves component `drop` rigidly by `correction` (left-multiplied) and merges it into `keep`.
  void JoinComponents(int keep, int drop, const Pose3& correction);
  // Places unknown or floating variable `key` at `pose` in the world (own component).
  void AnchorToWorld(uint64_t key, const Pose3& pose);
  SlamUpdateStats Solve(int iterations, double seconds);

  SlamGraphOptions options_;
  std::unique_ptr<ceres::Problem> problem_;
  std::unique_ptr<ceres::Manifold> manifold_;
  std::unique_ptr<ceres::LossFunction> cauchy_;
  std::map<uint64_t, Variable> variables_;
  std::map<int, std::set<uint64_t>> components_;   // component id -> members
  int own_component_ = -1;                         // component holding the prior
  int next_component_ = 0;
  std::vector<SlamFactor> pending_;
  std::vector<SlamFactor> factors_;                // inserted ones, for Chi2()
  size_t num_added_factors_ = 0;
  double new_cost_ = 0.0;  // cost of the factors added since the last solve, at insertion
  bool unconverged_ = false;  // the last bounded solve stopped early: the next Update() resumes it
  std::map<char, uint64_t> latest_submap_;
  // Covariance cache.
  std::map<uint64_t, std::pair<Pose3, Matrix6d>> covariance_cache_;
  size_t covariance_factor_count_ = 0;
  int covariance_computations_ = 0;
};

}  // namespace cairn
