#include "estimation/graph/pairwise_consistency.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <numeric>

#include <Eigen/Cholesky>

#include "estimation/graph/noise_scale.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

Matrix6d Covariance(const Matrix6d& information) {
  return information.ldlt().solve(Matrix6d::Identity());
}

// Dead reckoning of one odometry chain, indexed by position along it.
struct Chain {
  std::vector<Pose3> T_c_v;           // pose of each vertex in the chain's frame
  std::vector<Matrix6d> prefix;       // sum of the chain-frame covariances of the edges before it
  Pose3 Between(int a, int b) const { return T_c_v[static_cast<size_t>(a)].Inverse() * T_c_v[static_cast<size_t>(b)]; }
  Matrix6d Segment(int a, int b) const {
    return prefix[static_cast<size_t>(std::max(a, b))] - prefix[static_cast<size_t>(std::min(a, b))];
  }
};

// A closure oriented from the group's first chain (x) to its second (y).
struct Closure {
  size_t edge;
  int x, y;          // positions along the chains
  Pose3 T_x_y;       // measured
  Matrix6d W;        // its covariance in the first chain's frame
};

}  // namespace

double ChiSquareCdf(double x, int dof) {
  // Upper tail Q(x; k) by the recurrence Q(k + 2) = Q(k) + (x/2)^(k/2) e^(-x/2) / Gamma(k/2 + 1).
  if (!(x > 0.0)) return 0.0;
  double q = dof % 2 == 0 ? std::exp(-0.5 * x) : std::erfc(std::sqrt(0.5 * x));
  for (int k = dof % 2 == 0 ? 2 : 1; k + 2 <= dof; k += 2) {
    const double h = 0.5 * k;
    q += std::exp(h * std::log(0.5 * x) - 0.5 * x - std::lgamma(h + 1.0));
  }
  return 1.0 - q;
}

double ChiSquareQuantile(double probability, int dof) {
  double lo = 0.0, hi = 10.0 * dof + 100.0;
  for (int i = 0; i < 200; ++i) {
    const double mid = 0.5 * (lo + hi);
    (ChiSquareCdf(mid, dof) < probability ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

Expected<PairwiseConsistencyResult> FindConsistentLoopClosures(const PoseGraph& graph,
                                                               const PairwiseConsistencyOptions& options) {
  if (!(options.confidence > 0.0 && options.confidence < 1.0)) {
    return InvalidArgumentError("pairwise consistency: confidence must lie in (0, 1)");
  }
  PairwiseConsistencyResult result;
  result.keep.assign(graph.edges().size(), true);
  const int dof = graph.planar() ? 3 : 6;
  result.noise_scale = options.noise_scale > 0.0 ? options.noise_scale : 1.0;

  // Chains: walk the vertices in key order; a vertex continues its predecessor's chain when an
  // odometry edge joins them (the first one, should there be several).
  const size_t n = graph.num_vertices();
  std::vector<size_t> odometry_into(n, graph.edges().size());
  for (size_t k = 0; k < graph.edges().size(); ++k) {
    const auto& e = graph.edges()[k];
    const size_t to = graph.Find(e.to);
    if (IsOdometryEdge(e) && odometry_into[to] == graph.edges().size()) odometry_into[to] = k;
  }
  std::vector<size_t> by_key(n);
  std::iota(by_key.begin(), by_key.end(), size_t{0});
  std::sort(by_key.begin(), by_key.end(), [&](size_t a, size_t b) { return graph.ids()[a] < graph.ids()[b]; });
  std::vector<Chain> chains;
  std::vector<int> chain_of(n), position(n);
  for (size_t s = 0; s < n; ++s) {
    const size_t v = by_key[s];
    const size_t k = odometry_into[v];
    const bool continues = s > 0 && k < graph.edges().size() && graph.ids()[by_key[s - 1]] + 1 == graph.ids()[v];
    if (!continues) {
      chains.emplace_back();
      chains.back().T_c_v.push_back(Pose3());
      chains.back().prefix.push_back(Matrix6d::Zero());
    } else {
      Chain& c = chains.back();
      const Pose3 T_c_v = c.T_c_v.back() * graph.edges()[k].T_from_to;
      const Matrix6d A = Adjoint(T_c_v);
      c.T_c_v.push_back(T_c_v);
      c.prefix.push_back(c.prefix.back() +
                         A * Covariance(EffectiveInformation(graph.edges()[k])) * A.transpose());
    }
    chain_of[v] = static_cast<int>(chains.size()) - 1;
    position[v] = static_cast<int>(chains.back().T_c_v.size()) - 1;
  }

  // Closures, oriented and grouped by the (ordered) pair of chains they join.
  std::map<std::pair<int, int>, std::vector<Closure>> groups;
  for (size_t k = 0; k < graph.edges().size(); ++k) {
    const auto& e = graph.edges()[k];
    if (IsOdometryEdge(e)) continue;
    ++result.loop_closures;
    const size_t a = graph.Find(e.from), b = graph.Find(e.to);
    Closure c{k, position[a], position[b], e.T_from_to, Covariance(EffectiveInformation(e))};
    int ca = chain_of[a], cb = chain_of[b];
    if (ca > cb) {
      // z Exp(xi) inverted is z^-1 Exp(-Ad(z) xi).
      const Matrix6d A = Adjoint(c.T_x_y);
      c.W = A * c.W * A.transpose();
      c.T_x_y = c.T_x_y.Inverse();
      std::swap(c.x, c.y);
      std::swap(ca, cb);
    }
    const Matrix6d A = Adjoint(chains[static_cast<size_t>(ca)].T_c_v[static_cast<size_t>(c.x)] * c.T_x_y);
    c.W = A * c.W * A.transpose();
    groups[{ca, cb}].push_back(c);
  }
  result.groups = static_cast<int>(groups.size());

  // Squared Mahalanobis length of every pair's cycle, per group in pair order (i < j), and of
  // every closure's shortest cycle (fewest odometry edges).
  std::vector<std::vector<float>> cycle_chi2;
  std::vector<double> shortest_chi2;
  for (const auto& [chain_pair, closures] : groups) {
    std::vector<int> shortest_length(closures.size(), std::numeric_limits<int>::max());
    std::vector<double> shortest(closures.size(), 0.0);
    const Chain& r = chains[static_cast<size_t>(chain_pair.first)];
    const Chain& s = chains[static_cast<size_t>(chain_pair.second)];
    const bool one_chain = chain_pair.first == chain_pair.second;
    std::vector<float>& d2 = cycle_chi2.emplace_back();
    d2.reserve(closures.size() * (closures.size() - 1) / 2);
    for (size_t i = 0; i < closures.size(); ++i) {
      const Closure& ci = closures[i];
      const Pose3& T_r_xi = r.T_c_v[static_cast<size_t>(ci.x)];
      // The second chain's frame in the first's, as closure i places it.
      const Matrix6d A_r_s = one_chain ? Matrix6d::Identity()
                                       : Adjoint(T_r_xi * ci.T_x_y * s.T_c_v[static_cast<size_t>(ci.y)].Inverse());
      const Matrix6d A_r_xi = Adjoint(T_r_xi);
      for (size_t j = i + 1; j < closures.size(); ++j) {
        const Closure& cj = closures[j];
        // x_i -> y_i -> y_j -> x_j -> x_i should be the identity.
        const Pose3 cycle = ci.T_x_y * s.Between(ci.y, cj.y) * cj.T_x_y.Inverse() * r.Between(cj.x, ci.x);
        Vector6d e;
        e.head<3>() = cycle.t;
        e.tail<3>() = so3::Log(cycle.q);
        const Vector6d e_r = A_r_xi * e;
        Matrix6d S = ci.W + cj.W + r.Segment(ci.x, cj.x);
        const Matrix6d Ss = s.Segment(ci.y, cj.y);
        S += one_chain ? Ss : Matrix6d(A_r_s * Ss * A_r_s.transpose());
        const Eigen::LDLT<Matrix6d> ldlt(S);
        d2.push_back(static_cast<float>(e_r.dot(ldlt.solve(e_r))));
        const int length = std::abs(ci.x - cj.x) + std::abs(ci.y - cj.y);
        for (size_t m : {i, j}) {
          if (length >= shortest_length[m]) continue;
          shortest_length[m] = length;
          shortest[m] = d2.back();
        }
      }
    }
    result.pairs_tested += static_cast<int64_t>(d2.size());
    if (closures.size() > 1) shortest_chi2.insert(shortest_chi2.end(), shortest.begin(), shortest.end());
  }
  // The clique keeps a true closure only if its cycle with every other true closure of its group
  // passes: each pair is tested at the probability that makes all of a closure's pass with
  // `confidence` (in the largest group).
  size_t largest = 0;
  for (const auto& [chain_pair, closures] : groups) largest = std::max(largest, closures.size());
  const double pair_confidence = std::pow(options.confidence, 1.0 / std::max(1.0, largest - 1.0));
  result.threshold = result.noise_scale * ChiSquareQuantile(pair_confidence, dof);
  if (options.noise_scale <= 0.0) {
    // The scale of the closures' shortest cycles (see the header): most closures are true.
    const NoiseScaleEstimate estimate = EstimateNoiseScale(shortest_chi2, dof, pair_confidence);
    result.noise_scale = estimate.scale;
    result.threshold = estimate.threshold;
  }

  size_t group = 0;
  for (const auto& [chain_pair, closures] : groups) {
    const std::vector<float>& d2 = cycle_chi2[group++];
    BitRows consistent = MakeBitRows(closures.size());
    for (size_t i = 0, pair = 0; i < closures.size(); ++i) {
      for (size_t j = i + 1; j < closures.size(); ++j, ++pair) {
        if (d2[pair] <= result.threshold) SetEdge(consistent, i, j);
      }
    }
    const CliqueResult clique = MaximumClique(consistent, options.clique);
    result.exact = result.exact && clique.exact;
    std::vector<bool> in_clique(closures.size(), false);
    for (int m : clique.members) in_clique[static_cast<size_t>(m)] = true;
    for (size_t i = 0; i < closures.size(); ++i) {
      if (in_clique[i]) continue;
      result.keep[closures[i].edge] = false;
      ++result.rejected;
    }
  }
  return result;
}

}  // namespace cairn
