#pragma once
// A pose graph as stored in g2o files and solved by `cairn graph solve`: 6-D vertices keyed by
// 64-bit ids and relative-pose edges with 6x6 information. Multi-robot ids carry the robot letter
// in the top byte (key = letter * 2^56 + index). Planar (SE2) data is lifted to 3-D on import and
// keeps its isotropic SE-Sync weights from the original 3x3 information.

#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn {

struct Pose3 {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Eigen::Quaterniond q = Eigen::Quaterniond::Identity();

  Eigen::Matrix3d R() const { return q.toRotationMatrix(); }
  Pose3 operator*(const Pose3& o) const { return {t + q * o.t, (q * o.q).normalized()}; }
  Pose3 Inverse() const {
    const Eigen::Quaterniond qi = q.conjugate();
    return {-(qi * t), qi};
  }
};

using Matrix6d = Eigen::Matrix<double, 6, 6>;
using Vector6d = Eigen::Matrix<double, 6, 1>;

// Adjoint of T for the [t; rotation] tangent order: T Exp(xi) = Exp(Adjoint(T) xi) T, to first
// order also for the factors' perturbation (t + R dt, R Exp(dr)).
Matrix6d Adjoint(const Pose3& T);

// Multi-robot keys: the robot letter ('a', 'b', ...) in the top byte, the index below.
constexpr uint64_t MakeRobotKey(char robot, uint64_t index) {
  return (static_cast<uint64_t>(static_cast<unsigned char>(robot)) << 56) | index;
}
constexpr unsigned RobotOfKey(uint64_t key) { return static_cast<unsigned>(key >> 56); }
constexpr uint64_t IndexOfKey(uint64_t key) { return key & ((uint64_t{1} << 56) - 1); }

struct PoseGraphEdge {
  uint64_t from = 0;
  uint64_t to = 0;
  Pose3 T_from_to;                                   // measured pose of `to` in `from`
  Matrix6d information = Matrix6d::Identity();       // order: tx ty tz, rotation vector x y z
  // Isotropic weights of the SE-Sync objective (information-divergence minimizing, as SE-Sync
  // derives them): tau = d / tr(Sigma_t), kappa = planar ? I_theta : 3 / (2 tr(Sigma_R)).
  double kappa = 1.0;
  double tau = 1.0;
  bool planar = false;  // read from EDGE_SE2
  // False when `information` is not positive definite (some benchmark files carry such blocks);
  // its translation and rotation blocks still are, so kappa and tau exist (see
  // indefinite_information.h).
  bool definite = true;
};

class PoseGraph {
 public:
  // Adds or overwrites a vertex; returns its dense index.
  size_t SetVertex(uint64_t id, const Pose3& pose);
  bool HasVertex(uint64_t id) const { return index_.count(id) != 0; }
  // Dense index of `id`; adds an identity vertex when it is new.
  size_t IndexOf(uint64_t id);
  size_t Find(uint64_t id) const { return index_.at(id); }

  void AddEdge(const PoseGraphEdge& e);
  // Recomputes the isotropic weights of `e` from its (3-D) information.
  static void SetIsotropicWeights(PoseGraphEdge& e);

  size_t num_vertices() const { return ids_.size(); }
  const std::vector<uint64_t>& ids() const { return ids_; }
  std::vector<Pose3>& poses() { return poses_; }
  const std::vector<Pose3>& poses() const { return poses_; }
  const std::vector<PoseGraphEdge>& edges() const { return edges_; }
  std::vector<PoseGraphEdge>& edges() { return edges_; }
  // True when the file gave vertex estimates (manhattan, for one, has none).
  bool has_initial_estimate() const { return has_estimate_; }
  void set_has_initial_estimate(bool v) { has_estimate_ = v; }
  // Planar graphs (all edges from EDGE_SE2) are written back as SE2.
  bool planar() const;
  // Edges whose information is not positive definite, and where the first was read ("file:line").
  size_t indefinite_edges() const;
  const std::string& first_indefinite() const { return first_indefinite_; }
  void set_first_indefinite(const std::string& where) { first_indefinite_ = where; }

  // Connected components of the edge graph: component id per dense vertex index.
  std::vector<int> Components(int* count) const;

 private:
  std::vector<uint64_t> ids_;
  std::vector<Pose3> poses_;
  std::unordered_map<uint64_t, size_t> index_;
  std::vector<PoseGraphEdge> edges_;
  bool has_estimate_ = false;
  std::string first_indefinite_;
};

// The information an edge's statistics use (geodesic chi-square, noise scale, PCM, GNC): its own
// when positive definite, else diag(tau I, 2 kappa I), what the SE-Sync objective weighs it by
// near the optimum (||R(theta) - I||_F^2 = 2 theta^2 to second order).
Matrix6d EffectiveInformation(const PoseGraphEdge& e);
// Replaces an edge's information by the nearest positive-definite matrix (eigenvalues raised to at
// least 1e-9 of the largest one's magnitude) and recomputes its isotropic weights.
void ProjectToPositiveDefinite(PoseGraphEdge& e);

// Robot odometry: consecutive indices of one robot, from the lower to the higher.
constexpr bool IsOdometryEdge(const PoseGraphEdge& e) {
  return RobotOfKey(e.from) == RobotOfKey(e.to) && e.to == e.from + 1;
}

// Objectives evaluated in double, independent of the solver:
// SE-Sync: sum kappa*||R_j - R_i R_ij||_F^2 + tau*||t_j - t_i - R_i t_ij||^2 (no 1/2).
double SeSyncCost(const PoseGraph& g);
// Geodesic chi-square: sum e^T Info e with e = [t(E); Log(R(E))], E = T_ij^-1 T_i^-1 T_j.
double GeodesicChi2(const PoseGraph& g);
// The 6-vector error of one edge in the geodesic convention above.
Vector6d GeodesicError(const Pose3& T_w_i, const Pose3& T_w_j, const Pose3& T_i_j);

// Initial estimate by composing edges along a breadth-first spanning tree from the first vertex of
// each component (the usual odometry initialization); the root keeps its pose.
void InitializeFromSpanningTree(PoseGraph& g);

}  // namespace cairn
