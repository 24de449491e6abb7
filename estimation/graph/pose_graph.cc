#include "estimation/graph/pose_graph.h"

#include <queue>

#include <Eigen/Eigenvalues>

#include "estimation/math/so3.h"

namespace cairn {

Matrix6d Adjoint(const Pose3& T) {
  const Eigen::Matrix3d R = T.R();
  Matrix6d A = Matrix6d::Zero();
  A.topLeftCorner<3, 3>() = R;
  A.topRightCorner<3, 3>() = so3::Skew(T.t) * R;
  A.bottomRightCorner<3, 3>() = R;
  return A;
}

size_t PoseGraph::SetVertex(uint64_t id, const Pose3& pose) {
  const size_t i = IndexOf(id);
  poses_[i] = pose;
  return i;
}

size_t PoseGraph::IndexOf(uint64_t id) {
  auto [it, inserted] = index_.emplace(id, ids_.size());
  if (inserted) {
    ids_.push_back(id);
    poses_.emplace_back();
  }
  return it->second;
}

void PoseGraph::AddEdge(const PoseGraphEdge& e) {
  IndexOf(e.from);
  IndexOf(e.to);
  edges_.push_back(e);
}

void PoseGraph::SetIsotropicWeights(PoseGraphEdge& e) {
  if (e.planar) {
    e.tau = 2.0 / e.information.topLeftCorner<2, 2>().inverse().trace();
    e.kappa = e.information(5, 5);
  } else {
    e.tau = 3.0 / e.information.topLeftCorner<3, 3>().inverse().trace();
    e.kappa = 3.0 / (2.0 * e.information.bottomRightCorner<3, 3>().inverse().trace());
  }
}

Matrix6d EffectiveInformation(const PoseGraphEdge& e) {
  if (e.definite) return e.information;
  Vector6d d;
  d << e.tau, e.tau, e.tau, 2 * e.kappa, 2 * e.kappa, 2 * e.kappa;
  return d.asDiagonal();
}

void ProjectToPositiveDefinite(PoseGraphEdge& e) {
  const Eigen::SelfAdjointEigenSolver<Matrix6d> eig(0.5 * (e.information + e.information.transpose()));
  const double floor = 1e-9 * eig.eigenvalues().cwiseAbs().maxCoeff();
  const Vector6d clamped = eig.eigenvalues().cwiseMax(floor);
  e.information = eig.eigenvectors() * clamped.asDiagonal() * eig.eigenvectors().transpose();
  e.definite = true;
  PoseGraph::SetIsotropicWeights(e);
}

size_t PoseGraph::indefinite_edges() const {
  size_t n = 0;
  for (const auto& e : edges_) n += e.definite ? 0 : 1;
  return n;
}

bool PoseGraph::planar() const {
  if (edges_.empty()) return false;
  for (const auto& e : edges_) {
    if (!e.planar) return false;
  }
  return true;
}

std::vector<int> PoseGraph::Components(int* count) const {
  std::vector<std::vector<size_t>> adjacency(ids_.size());
  for (const auto& e : edges_) {
    const size_t a = index_.at(e.from), b = index_.at(e.to);
    adjacency[a].push_back(b);
    adjacency[b].push_back(a);
  }
  std::vector<int> component(ids_.size(), -1);
  int n = 0;
  for (size_t root = 0; root < ids_.size(); ++root) {
    if (component[root] >= 0) continue;
    std::queue<size_t> queue;
    queue.push(root);
    component[root] = n;
    while (!queue.empty()) {
      const size_t v = queue.front();
      queue.pop();
      for (size_t w : adjacency[v]) {
        if (component[w] < 0) {
          component[w] = n;
          queue.push(w);
        }
      }
    }
    ++n;
  }
  if (count != nullptr) *count = n;
  return component;
}

double SeSyncCost(const PoseGraph& g) {
  double cost = 0.0;
  for (const auto& e : g.edges()) {
    const Pose3& a = g.poses()[g.Find(e.from)];
    const Pose3& b = g.poses()[g.Find(e.to)];
    const Eigen::Matrix3d Ra = a.R();
    cost += e.kappa * (b.R() - Ra * e.T_from_to.R()).squaredNorm();
    cost += e.tau * (b.t - a.t - Ra * e.T_from_to.t).squaredNorm();
  }
  return cost;
}

Vector6d GeodesicError(const Pose3& T_w_i, const Pose3& T_w_j, const Pose3& T_i_j) {
  const Pose3 E = T_i_j.Inverse() * (T_w_i.Inverse() * T_w_j);
  Vector6d err;
  err.head<3>() = E.t;
  err.tail<3>() = so3::Log(E.q);
  return err;
}

double GeodesicChi2(const PoseGraph& g) {
  double chi2 = 0.0;
  for (const auto& e : g.edges()) {
    const Vector6d err =
        GeodesicError(g.poses()[g.Find(e.from)], g.poses()[g.Find(e.to)], e.T_from_to);
    chi2 += err.dot(EffectiveInformation(e) * err);
  }
  return chi2;
}

void InitializeFromSpanningTree(PoseGraph& g) {
  const size_t n = g.num_vertices();
  std::vector<std::vector<std::pair<size_t, int>>> adjacency(n);  // edge index, direction
  for (size_t k = 0; k < g.edges().size(); ++k) {
    const auto& e = g.edges()[k];
    adjacency[g.Find(e.from)].emplace_back(k, +1);
    adjacency[g.Find(e.to)].emplace_back(k, -1);
  }
  std::vector<bool> seen(n, false);
  // Grows the tree from `queue` over the edges `use` accepts.
  auto grow = [&](std::queue<size_t>& queue, bool odometry_only) {
    while (!queue.empty()) {
      const size_t v = queue.front();
      queue.pop();
      for (const auto& [k, dir] : adjacency[v]) {
        const auto& e = g.edges()[k];
        if (odometry_only && !IsOdometryEdge(e)) continue;
        const size_t w = dir > 0 ? g.Find(e.to) : g.Find(e.from);
        if (seen[w]) continue;
        seen[w] = true;
        g.poses()[w] = dir > 0 ? g.poses()[v] * e.T_from_to : g.poses()[v] * e.T_from_to.Inverse();
        queue.push(w);
      }
    }
  };
  // Odometry chains first so that loop closures only bridge what odometry does not reach.
  for (size_t root = 0; root < n; ++root) {
    if (seen[root]) continue;
    seen[root] = true;
    std::queue<size_t> queue;
    queue.push(root);
    grow(queue, true);
    // Then everything reachable from the chains grown so far.
    for (size_t v = 0; v < n; ++v) {
      if (seen[v]) queue.push(v);
    }
    grow(queue, false);
  }
}

}  // namespace cairn
