#include "mapping/matching/four_dof_ransac.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

namespace cairn {
namespace {

// Uniform in [0, n) from the engine's raw output. Rejection keeps it unbiased and, unlike the
// standard distributions, gives the same draws under every standard library.
size_t DrawIndex(std::mt19937_64& rng, size_t n) {
  constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
  const uint64_t range = n;
  const uint64_t limit = kMax - kMax % range;  // a multiple of range
  uint64_t r = rng();
  while (r >= limit) r = rng();
  return static_cast<size_t>(r % range);
}

struct Score {
  size_t inliers = 0;
  double sum_sq = 0.0;  // of the inliers' distances

  bool BetterThan(const Score& o) const {
    return inliers > o.inliers || (inliers == o.inliers && sum_sq < o.sum_sq);
  }
};

Score Evaluate(const FourDofTransform& T, std::span<const Eigen::Vector3d> source,
               std::span<const Eigen::Vector3d> target, std::span<const size_t> valid, double threshold_sq) {
  Score s;
  for (const size_t i : valid) {
    const double d2 = (T * source[i] - target[i]).squaredNorm();
    if (d2 <= threshold_sq) {
      ++s.inliers;
      s.sum_sq += d2;
    }
  }
  return s;
}

void CollectInliers(const FourDofTransform& T, std::span<const Eigen::Vector3d> source,
                    std::span<const Eigen::Vector3d> target, std::span<const size_t> valid,
                    double threshold_sq, std::vector<size_t>* inliers) {
  inliers->clear();
  for (const size_t i : valid) {
    if ((T * source[i] - target[i]).squaredNorm() <= threshold_sq) inliers->push_back(i);
  }
}

// Samples needed to draw one pair of distinct inliers with probability `confidence` when `k` of
// the `n` correspondences are inliers; at most `cap`.
int64_t RequiredSamples(size_t k, size_t n, double confidence, int64_t cap) {
  if (k < 2) return cap;
  const double p_pair = (static_cast<double>(k) * static_cast<double>(k - 1)) /
                        (static_cast<double>(n) * static_cast<double>(n - 1));
  if (p_pair >= 1.0) return 1;
  const double needed = std::ceil(std::log(1.0 - confidence) / std::log1p(-p_pair));
  if (!(needed < static_cast<double>(cap))) return cap;
  return std::max<int64_t>(1, static_cast<int64_t>(needed));
}

}  // namespace

Status FourDofRansacOptions::Validate() const {
  if (!(inlier_threshold > 0.0)) return InvalidArgumentError("ransac: inlier_threshold must be > 0");
  if (!(min_horizontal_separation >= 0.0))
    return InvalidArgumentError("ransac: min_horizontal_separation must be >= 0");
  if (!(max_pair_length_difference >= 0.0))
    return InvalidArgumentError("ransac: max_pair_length_difference must be >= 0");
  if (max_iterations < 1) return InvalidArgumentError("ransac: max_iterations must be >= 1");
  if (!(confidence > 0.0 && confidence < 1.0))
    return InvalidArgumentError("ransac: confidence must be in (0, 1)");
  if (min_inliers < 2) return InvalidArgumentError("ransac: min_inliers must be >= 2");
  if (refine_rounds < 0) return InvalidArgumentError("ransac: refine_rounds must be >= 0");
  return Status::Ok();
}

std::optional<FourDofTransform> FourDofRansac::SolveTwoPoint(const Eigen::Vector3d& source0,
                                                             const Eigen::Vector3d& source1,
                                                             const Eigen::Vector3d& target0,
                                                             const Eigen::Vector3d& target1) const {
  // Eq. 6.5: the pair difference with its gravity component removed.
  const Eigen::Vector2d d_b = (source1 - source0).head<2>();
  const Eigen::Vector2d d_a = (target1 - target0).head<2>();
  const double len_b = d_b.norm();
  const double len_a = d_a.norm();
  const double min_len = std::max(options_.min_horizontal_separation, 1e-9);
  if (!(len_b >= min_len) || !(len_a >= min_len)) return std::nullopt;
  // A 4-DoF motion keeps horizontal lengths and height differences; a sample that changes either
  // holds a wrong correspondence and would only spend an evaluation.
  const double tol = options_.max_pair_length_difference;
  if (!(std::abs(len_a - len_b) <= tol)) return std::nullopt;
  if (!(std::abs((target1.z() - target0.z()) - (source1.z() - source0.z())) <= tol)) return std::nullopt;
  // Eqs. 6.5, 6.6: R_i has the columns d'_i/|d'_i|, (d'_i x z)/|.|, z, so R = R_A R_B^T is the
  // rotation about z taking B's pair direction onto A's, i.e. by the difference of their headings.
  const double yaw = std::atan2(d_a.y(), d_a.x()) - std::atan2(d_b.y(), d_b.x());
  const FourDofTransform rotation(Eigen::Vector3d::Zero(), yaw);
  // Eq. 6.7: t = mean_A - R mean_B.
  const Eigen::Vector3d mean_a = 0.5 * (target0 + target1);
  const Eigen::Vector3d mean_b = 0.5 * (source0 + source1);
  return FourDofTransform(mean_a - rotation * mean_b, yaw);
}

std::optional<FourDofTransform> FourDofRansac::FitLeastSquares(std::span<const Eigen::Vector3d> source_b,
                                                               std::span<const Eigen::Vector3d> target_a,
                                                               std::span<const size_t> indices) {
  if (indices.size() < 2) return std::nullopt;
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero();
  Eigen::Vector3d mean_b = Eigen::Vector3d::Zero();
  for (const size_t i : indices) {
    mean_a += target_a[i];
    mean_b += source_b[i];
  }
  const double n = static_cast<double>(indices.size());
  mean_a /= n;
  mean_b /= n;
  // With R the rotation by yaw, sum |R b_i - a_i|^2 over the centred points is least where
  // sum a_i . R b_i = cos(yaw) * c + sin(yaw) * s is largest; the heights do not depend on yaw.
  double c = 0.0;
  double s = 0.0;
  double spread = 0.0;
  for (const size_t i : indices) {
    const Eigen::Vector2d a = (target_a[i] - mean_a).head<2>();
    const Eigen::Vector2d b = (source_b[i] - mean_b).head<2>();
    c += a.x() * b.x() + a.y() * b.y();
    s += a.y() * b.x() - a.x() * b.y();
    spread += b.squaredNorm();
  }
  if (!(spread > 1e-12 * n) || !(std::hypot(c, s) > 0.0)) return std::nullopt;
  const double yaw = std::atan2(s, c);
  const FourDofTransform rotation(Eigen::Vector3d::Zero(), yaw);
  return FourDofTransform(mean_a - rotation * mean_b, yaw);
}

Expected<FourDofRansacResult> FourDofRansac::Estimate(std::span<const Eigen::Vector3d> source_b,
                                                      std::span<const Eigen::Vector3d> target_a) const {
  CAIRN_RETURN_IF_ERROR(options_.Validate());
  if (source_b.size() != target_a.size())
    return InvalidArgumentError("ransac: " + std::to_string(source_b.size()) + " source points but " +
                                std::to_string(target_a.size()) + " target points");
  FourDofRansacResult result;
  std::vector<size_t> valid;
  valid.reserve(source_b.size());
  for (size_t i = 0; i < source_b.size(); ++i) {
    if (source_b[i].allFinite() && target_a[i].allFinite()) valid.push_back(i);
  }
  result.skipped_non_finite = source_b.size() - valid.size();
  const size_t needed = static_cast<size_t>(std::max<int64_t>(2, options_.min_inliers));
  if (valid.size() < needed)
    return FailedPreconditionError("ransac: too few correspondences: " + std::to_string(valid.size()) +
                                   " finite (" + std::to_string(result.skipped_non_finite) +
                                   " non-finite skipped), need " + std::to_string(needed));

  const double threshold_sq = options_.inlier_threshold * options_.inlier_threshold;
  std::mt19937_64 rng(options_.seed);
  Score best;
  FourDofTransform best_T;
  bool have_best = false;
  int64_t required = options_.max_iterations;
  int64_t it = 0;
  for (; it < options_.max_iterations && it < required; ++it) {
    // Two distinct indices, drawn one after the other (a fixed order whatever the compiler).
    const size_t i = DrawIndex(rng, valid.size());
    size_t j = DrawIndex(rng, valid.size() - 1);
    if (j >= i) ++j;
    const std::optional<FourDofTransform> T =
        SolveTwoPoint(source_b[valid[i]], source_b[valid[j]], target_a[valid[i]], target_a[valid[j]]);
    if (!T) {
      ++result.degenerate_samples;
      continue;
    }
    const Score s = Evaluate(*T, source_b, target_a, valid, threshold_sq);
    if (!have_best || s.BetterThan(best)) {
      best = s;
      best_T = *T;
      have_best = true;
      required = RequiredSamples(s.inliers, valid.size(), options_.confidence, options_.max_iterations);
    }
  }
  result.iterations = it;
  if (!have_best)
    return NotFoundError("ransac: no consensus: all " + std::to_string(it) + " samples were degenerate");
  if (best.inliers < static_cast<size_t>(options_.min_inliers))
    return NotFoundError("ransac: no consensus: the best of " + std::to_string(it) + " hypotheses has " +
                         std::to_string(best.inliers) + " inliers, need " +
                         std::to_string(options_.min_inliers));

  CollectInliers(best_T, source_b, target_a, valid, threshold_sq, &result.inliers);
  std::vector<size_t> refit_inliers;
  for (int64_t round = 0; round < options_.refine_rounds; ++round) {
    const std::optional<FourDofTransform> T = FitLeastSquares(source_b, target_a, result.inliers);
    if (!T) break;
    const Score s = Evaluate(*T, source_b, target_a, valid, threshold_sq);
    if (!s.BetterThan(best)) break;
    best = s;
    best_T = *T;
    CollectInliers(best_T, source_b, target_a, valid, threshold_sq, &refit_inliers);
    const bool same = refit_inliers == result.inliers;
    result.inliers.swap(refit_inliers);
    if (same) break;
  }
  result.T_a_b = best_T;
  result.inlier_rms = std::sqrt(best.sum_sq / static_cast<double>(best.inliers));
  return result;
}

}  // namespace cairn
