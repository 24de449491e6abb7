#include "mapping/matching/four_dof_icp.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include <nanoflann.hpp>

#include "estimation/math/small_cholesky.h"
#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

// The finite target points as nanoflann reads them.
struct IcpCloudAdaptor {
  const std::vector<Eigen::Vector3d>* points;

  size_t kdtree_get_point_count() const { return points->size(); }
  double kdtree_get_pt(size_t i, size_t dim) const { return (*points)[i][static_cast<Eigen::Index>(dim)]; }
  template <class BoundingBox>
  bool kdtree_get_bbox(BoundingBox& /*bb*/) const {
    return false;  // let the tree compute it
  }
};

using IcpKdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, IcpCloudAdaptor>,
                                                   IcpCloudAdaptor, 3, uint32_t>;

std::string Num(double v) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "%.4g", v);
  return buf;
}

// The finite points of `in`; the count of the others goes to `skipped`.
std::vector<Eigen::Vector3d> FinitePoints(std::span<const Eigen::Vector3d> in, size_t* skipped) {
  std::vector<Eigen::Vector3d> out;
  out.reserve(in.size());
  for (const Eigen::Vector3d& p : in) {
    if (p.allFinite()) out.push_back(p);
  }
  *skipped = in.size() - out.size();
  return out;
}

// Unit normals of the target points from the PCA of their neighbourhoods; `good` marks those
// whose neighbourhood is a well-sampled plane. Returns the count of good ones.
size_t ComputeNormals(const IcpKdTree& tree, const std::vector<Eigen::Vector3d>& points,
                      const FourDofIcpOptions& o, std::vector<Eigen::Vector3d>* normals,
                      std::vector<uint8_t>* good) {
  const size_t k = std::min(static_cast<size_t>(o.normal_neighbours), points.size());
  std::vector<uint32_t> idx(k);
  std::vector<double> d2(k);
  normals->assign(points.size(), Eigen::Vector3d::UnitZ());
  good->assign(points.size(), 0);
  const double r2 = o.normal_radius * o.normal_radius;
  size_t count = 0;
  for (size_t i = 0; i < points.size(); ++i) {
    const size_t found = tree.knnSearch(points[i].data(), k, idx.data(), d2.data());
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    size_t m = 0;
    for (size_t j = 0; j < found; ++j) {
      if (d2[j] > r2) continue;
      mean += points[idx[j]];
      ++m;
    }
    if (m < static_cast<size_t>(o.min_normal_neighbours)) continue;
    mean /= static_cast<double>(m);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (size_t j = 0; j < found; ++j) {
      if (d2[j] > r2) continue;
      const Eigen::Vector3d d = points[idx[j]] - mean;
      cov.noalias() += d * d.transpose();
    }
    Eigen::Vector3d values;
    Eigen::Matrix3d vectors;
    if (!SymmetricEigen(cov, &values, &vectors)) continue;
    const double sum = values.sum();
    if (!(sum > 0.0) || !(values(2) > 0.0)) continue;
    if (values(0) > o.max_surface_variation * sum) continue;   // not flat: an edge, a corner, noise
    if (values(1) < o.min_planar_ratio * values(2)) continue;  // a line: the normal is undefined
    (*normals)[i] = vectors.col(0).normalized();
    (*good)[i] = 1;
    ++count;
  }
  return count;
}

// The normal equations of one correspondence pass, and what the observability check needs.
struct Pass {
  size_t n = 0;
  Eigen::Matrix4d H = Eigen::Matrix4d::Zero();  // J^T J
  Eigen::Vector4d g = Eigen::Vector4d::Zero();  // J^T r
  double sum_r2 = 0.0;
  Eigen::Vector3d sum_q = Eigen::Vector3d::Zero();
  double sum_qh2 = 0.0;  // sum of |q_xy|^2
};

// Builds the correspondence sets; its scratch arrays are allocated once, not per iteration.
class Aligner {
 public:
  Aligner(const FourDofIcpOptions& o, const std::vector<Eigen::Vector3d>& source,
          const std::vector<Eigen::Vector3d>& target, const IcpKdTree& tree,
          const std::vector<Eigen::Vector3d>& normals, const std::vector<uint8_t>& good)
      : unique_(o.unique_targets),
        source_(source),
        target_(target),
        tree_(tree),
        normals_(normals),
        good_(good),
        nn_(source.size(), kNone),
        claim_d2_(o.unique_targets ? target.size() : 0, kFree),
        claim_(o.unique_targets ? target.size() : 0, kNone),
        pairs_(source.size()) {}

  Pass Run(const FourDofTransform& T, double gate) {
    const double gate2 = gate * gate;
    for (size_t s = 0; s < source_.size(); ++s) {
      const Eigen::Vector3d q = T * source_[s];
      uint32_t idx = 0;
      double d2 = 0.0;
      nn_[s] = kNone;
      if (tree_.knnSearch(q.data(), 1, &idx, &d2) != 1) continue;
      if (d2 > gate2 || good_[idx] == 0) continue;
      nn_[s] = idx;
      // The closest source point claims the target point (the first one on a tie).
      if (unique_ && d2 < claim_d2_[idx]) {
        claim_d2_[idx] = d2;
        claim_[idx] = static_cast<uint32_t>(s);
      }
    }
    Pass pass;
    pair_count_ = 0;
    for (size_t s = 0; s < source_.size(); ++s) {
      const uint32_t idx = nn_[s];
      if (idx == kNone) continue;
      if (unique_) {
        const bool mine = claim_[idx] == s;
        claim_d2_[idx] = kFree;  // reset for the next pass; only the touched entries
        if (!mine) continue;
      }
      pairs_[pair_count_++] = {static_cast<uint32_t>(s), idx};
      Add(T, source_[s], idx, &pass);
    }
    return pass;
  }

  // The pairs of the last Run() again, at another estimate.
  Pass RunFrozen(const FourDofTransform& T) const {
    Pass pass;
    for (size_t i = 0; i < pair_count_; ++i) Add(T, source_[pairs_[i].first], pairs_[i].second, &pass);
    return pass;
  }

 private:
  void Add(const FourDofTransform& T, const Eigen::Vector3d& p, uint32_t idx, Pass* pass) const {
    const Eigen::Vector3d q = T * p;
    const Eigen::Vector3d& nrm = normals_[idx];
    const double r = nrm.dot(q - target_[idx]);
    const Eigen::Vector3d v = q - T.translation();  // R p
    Eigen::Vector4d J;
    J << nrm, nrm.y() * v.x() - nrm.x() * v.y();  // n . (z x R p)
    pass->H.noalias() += J * J.transpose();
    pass->g += J * r;
    pass->sum_r2 += r * r;
    pass->sum_q += q;
    pass->sum_qh2 += q.head<2>().squaredNorm();
    ++pass->n;
  }

  static constexpr uint32_t kNone = std::numeric_limits<uint32_t>::max();
  static constexpr double kFree = std::numeric_limits<double>::infinity();

  bool unique_;
  const std::vector<Eigen::Vector3d>& source_;
  const std::vector<Eigen::Vector3d>& target_;
  const IcpKdTree& tree_;
  const std::vector<Eigen::Vector3d>& normals_;
  const std::vector<uint8_t>& good_;
  std::vector<uint32_t> nn_;      // per source point: its paired target point or kNone
  std::vector<double> claim_d2_;  // per target point: distance of its closest source point
  std::vector<uint32_t> claim_;   // per target point: that source point
  std::vector<std::pair<uint32_t, uint32_t>> pairs_;  // (source, target) of the last Run()
  size_t pair_count_ = 0;
};

// The smallest eigenvalue of the per-correspondence information with yaw taken about the
// centroid of the paired points and scaled by their RMS horizontal distance from it (see the
// header); 0 when the points have no horizontal extent.
double Observability(const Pass& pass, const FourDofTransform& T) {
  if (pass.n == 0) return 0.0;
  const double n = static_cast<double>(pass.n);
  const Eigen::Vector3d c = pass.sum_q / n;
  const double L2 = pass.sum_qh2 / n - c.head<2>().squaredNorm();
  if (!(L2 > 1e-12)) return 0.0;
  // J_c = M J: dr/d(yaw about c) = dr/d(yaw) - n . w with w = z x (c - t).
  const Eigen::Vector3d ct = c - T.translation();
  const Eigen::Vector3d w(-ct.y(), ct.x(), 0.0);
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity();
  M.block<1, 3>(3, 0) = -w.transpose();
  const Eigen::Matrix4d Hc = M * pass.H * M.transpose();
  const Eigen::Vector4d scale(1.0, 1.0, 1.0, 1.0 / std::sqrt(L2));
  Eigen::Matrix4d Hs = scale.asDiagonal() * Hc * scale.asDiagonal();
  Hs /= n;
  // The compiled 6x6 solver with two padding eigenvalues above all of Hs's (its trace bounds them).
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  A.topLeftCorner<4, 4>() = Hs;
  A(4, 4) = A(5, 5) = Hs.trace() + 1.0;
  Eigen::Matrix<double, 6, 1> values;
  Eigen::Matrix<double, 6, 6> vectors;
  if (!SymmetricEigen(A, &values, &vectors)) return 0.0;
  return std::max(0.0, values(0));
}

}  // namespace

Status FourDofIcpOptions::Validate() const {
  if (max_iterations < 1) return InvalidArgumentError("icp: max_iterations must be >= 1");
  if (!(min_correspondence_distance > 0.0) || !(max_correspondence_distance >= min_correspondence_distance))
    return InvalidArgumentError("icp: need 0 < min_correspondence_distance <= max_correspondence_distance");
  if (!(gate_shrink > 0.0 && gate_shrink <= 1.0))
    return InvalidArgumentError("icp: gate_shrink must be in (0, 1]");
  if (normal_neighbours < 3 || min_normal_neighbours < 3 || min_normal_neighbours > normal_neighbours)
    return InvalidArgumentError("icp: need 3 <= min_normal_neighbours <= normal_neighbours");
  if (!(normal_radius > 0.0)) return InvalidArgumentError("icp: normal_radius must be > 0");
  if (!(max_surface_variation >= 0.0) || !(min_planar_ratio >= 0.0))
    return InvalidArgumentError("icp: max_surface_variation and min_planar_ratio must be >= 0");
  if (min_correspondences < 5) return InvalidArgumentError("icp: min_correspondences must be >= 5");
  if (!(min_observability >= 0.0)) return InvalidArgumentError("icp: min_observability must be >= 0");
  if (!(translation_tolerance >= 0.0) || !(yaw_tolerance >= 0.0) || !(max_step_sigmas >= 0.0))
    return InvalidArgumentError("icp: tolerances must be >= 0");
  if (freeze_after < 1) return InvalidArgumentError("icp: freeze_after must be >= 1");
  return Status::Ok();
}

FourDofIcpResult FourDofIcp::Align(std::span<const Eigen::Vector3d> target_a,
                                   std::span<const Eigen::Vector3d> source_b,
                                   const FourDofTransform& T_a_b_initial) const {
  FourDofIcpResult res;
  res.T_a_b = T_a_b_initial;
  if (Status s = options_.Validate(); !s.ok()) {
    res.status = s;
    return res;
  }
  if (!T_a_b_initial.translation().allFinite() || !std::isfinite(T_a_b_initial.yaw())) {
    res.status = InvalidArgumentError("icp: non-finite initial transform");
    return res;
  }
  const std::vector<Eigen::Vector3d> target = FinitePoints(target_a, &res.skipped_target);
  const std::vector<Eigen::Vector3d> source = FinitePoints(source_b, &res.skipped_source);
  const size_t min_points = static_cast<size_t>(options_.min_correspondences);
  const auto too_few = [&](const char* name, const std::vector<Eigen::Vector3d>& cloud, size_t skipped) {
    if (cloud.size() >= min_points) return false;
    const std::string what = cloud.empty() && skipped == 0
                                 ? std::string("is empty")
                                 : "has " + std::to_string(cloud.size()) + " finite points (" +
                                       std::to_string(skipped) + " non-finite skipped)";
    res.status = FailedPreconditionError(std::string("icp: ") + name + " cloud " + what + ", need " +
                                         std::to_string(min_points));
    return true;
  };
  if (too_few("source", source, res.skipped_source) || too_few("target", target, res.skipped_target))
    return res;

  const IcpCloudAdaptor adaptor{&target};
  const IcpKdTree tree(3, adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(10));
  std::vector<Eigen::Vector3d> normals;
  std::vector<uint8_t> good;
  res.target_normals = ComputeNormals(tree, target, options_, &normals, &good);
  if (res.target_normals < min_points) {
    res.status = FailedPreconditionError(
        "icp: only " + std::to_string(res.target_normals) + " of " + std::to_string(target.size()) +
        " target points have a planar neighbourhood, need " + std::to_string(min_points));
    return res;
  }

  Aligner aligner(options_, source, target, tree, normals, good);
  FourDofTransform T = T_a_b_initial;
  double gate = options_.max_correspondence_distance;
  Eigen::Vector4d step = Eigen::Vector4d::Zero();
  Eigen::Matrix4d L = Eigen::Matrix4d::Zero();  // Cholesky factor of the last usable pass's J^T J
  // Checks one pass; false (with the status set) when it cannot be used.
  const auto usable = [&](const Pass& pass, double gate_used) {
    res.inliers = pass.n;
    if (pass.n < min_points) {
      res.status = NotFoundError("icp: too few overlapping points: " + std::to_string(pass.n) + " within " +
                                 Num(gate_used) + " m, need " + std::to_string(min_points));
      return false;
    }
    res.observability = Observability(pass, T);
    if (res.observability < options_.min_observability) {
      res.degenerate = true;
      res.status = FailedPreconditionError("icp: degenerate geometry: observability " +
                                           Num(res.observability) + " < " + Num(options_.min_observability) +
                                           " (the clouds leave a combination of x, y, z, yaw free)");
      return false;
    }
    if (!small_cholesky::Factor<4>(pass.H, &L)) {
      res.status = InternalError("icp: singular normal equations");
      return false;
    }
    return true;
  };

  // Within the tolerances: no motion worth another pass.
  const auto same = [&](const FourDofTransform& a, const FourDofTransform& b) {
    return (a.translation() - b.translation()).norm() < options_.translation_tolerance &&
           std::abs(WrapAngle(a.yaw() - b.yaw())) < options_.yaw_tolerance;
  };
  // Near the optimum the pairs can cycle through a few sets, and the estimate with them, by
  // less than its standard deviation but for ever: after freeze_after passes at the gate's floor
  // the pairs stay as they are and Gauss-Newton converges on them.
  int64_t passes_at_floor = 0;
  bool frozen = false;
  for (int64_t it = 0; it < options_.max_iterations; ++it) {
    const Pass pass = frozen ? aligner.RunFrozen(T) : aligner.Run(T, gate);
    if (!usable(pass, gate)) return res;
    step = -pass.g;
    small_cholesky::SolveLower<4>(L, step);
    small_cholesky::SolveLowerTransposed<4>(L, step);
    const FourDofTransform previous = T;
    T = FourDofTransform(T.translation() + step.head<3>(), T.yaw() + step(3));
    res.T_a_b = T;
    res.iterations = it + 1;
    if (gate <= options_.min_correspondence_distance) {
      // The step in standard deviations of the estimate: step^T (J^T J / sigma^2) step, where
      // step^T J^T J step = -step . J^T r for the Gauss-Newton step.
      const double sigma2 = pass.sum_r2 / (static_cast<double>(pass.n) - 4.0);
      const double step_sigmas2 = -step.dot(pass.g) / sigma2;
      if (same(T, previous) || step_sigmas2 < options_.max_step_sigmas * options_.max_step_sigmas) {
        res.converged = true;
        break;
      }
      frozen = frozen || ++passes_at_floor >= options_.freeze_after;
    }
    gate = std::max(options_.min_correspondence_distance, gate * options_.gate_shrink);
  }

  // The final pass at the final estimate: inliers, residual and covariance.
  const Pass pass = frozen ? aligner.RunFrozen(T) : aligner.Run(T, gate);
  if (!usable(pass, gate)) return res;
  const double n = static_cast<double>(pass.n);
  res.rms = std::sqrt(pass.sum_r2 / n);
  res.overlap = n / static_cast<double>(source.size());
  if (!res.converged) {
    res.status = TimeoutError("icp: not converged within " + std::to_string(options_.max_iterations) +
                              " iterations (last step " + Num(step.head<3>().norm()) + " m, " +
                              Num(std::abs(step(3))) + " rad)");
    return res;
  }
  // Sigma = sigma^2 (J^T J)^-1, column by column from the Cholesky factor of J^T J.
  const double sigma2 = pass.sum_r2 / (n - 4.0);
  Eigen::Matrix4d inverse;
  for (int i = 0; i < 4; ++i) {
    Eigen::Vector4d e = Eigen::Vector4d::Unit(i);
    small_cholesky::SolveLower<4>(L, e);
    small_cholesky::SolveLowerTransposed<4>(L, e);
    inverse.col(i) = e;
  }
  res.covariance = sigma2 * 0.5 * (inverse + inverse.transpose());
  res.status = Status::Ok();
  return res;
}

}  // namespace cairn
