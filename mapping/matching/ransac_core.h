#pragma once
// The loop shared by the matcher's RANSACs (four_dof_ransac.h, six_dof_ransac.h): deterministic
// sampling (the same under every standard library, so a seed names one result everywhere), scoring,
// the adaptive stop, and the least-squares refinement of the best hypothesis on its inliers.

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"
#include "mapping/matching/four_dof_ransac.h"

namespace cairn {

// Uniform in [0, n) from the engine's raw output. Rejection keeps it unbiased and, unlike the
// standard distributions, gives the same draws under every standard library.
inline size_t DrawIndex(std::mt19937_64& rng, size_t n) {
  constexpr uint64_t kMax = std::numeric_limits<uint64_t>::max();
  const uint64_t range = n;
  const uint64_t limit = kMax - kMax % range;  // a multiple of range
  uint64_t r = rng();
  while (r >= limit) r = rng();
  return static_cast<size_t>(r % range);
}

// Samples needed to draw `sample_size` distinct inliers with probability `confidence` when `k` of
// the `n` correspondences are inliers; at most `cap`.
inline int64_t RequiredSamples(size_t k, size_t n, size_t sample_size, double confidence, int64_t cap) {
  if (k < sample_size || n < sample_size) return cap;
  double numerator = 1.0, denominator = 1.0;
  for (size_t j = 0; j < sample_size; ++j) {
    numerator *= static_cast<double>(k - j);
    denominator *= static_cast<double>(n - j);
  }
  const double p_sample = numerator / denominator;
  if (p_sample >= 1.0) return 1;
  const double needed = std::ceil(std::log(1.0 - confidence) / std::log1p(-p_sample));
  if (!(needed < static_cast<double>(cap))) return cap;
  return std::max<int64_t>(1, static_cast<int64_t>(needed));
}


struct RansacScore {
  size_t inliers = 0;
  double sum_sq = 0.0;  // of the inliers' distances

  bool BetterThan(const RansacScore& o) const {
    return inliers > o.inliers || (inliers == o.inliers && sum_sq < o.sum_sq);
  }
};

template <class Transform>
RansacScore EvaluateRansac(const Transform& T, std::span<const Eigen::Vector3d> source,
               std::span<const Eigen::Vector3d> target, std::span<const size_t> valid, double threshold_sq) {
  RansacScore s;
  for (const size_t i : valid) {
    const double d2 = (T * source[i] - target[i]).squaredNorm();
    if (d2 <= threshold_sq) {
      ++s.inliers;
      s.sum_sq += d2;
    }
  }
  return s;
}

template <class Transform>
void CollectRansacInliers(const Transform& T, std::span<const Eigen::Vector3d> source,
                    std::span<const Eigen::Vector3d> target, std::span<const size_t> valid,
                    double threshold_sq, std::vector<size_t>* inliers) {
  inliers->clear();
  for (const size_t i : valid) {
    if ((T * source[i] - target[i]).squaredNorm() <= threshold_sq) inliers->push_back(i);
  }
}

// RANSAC over the finite correspondences source_b[i] <-> target_a[i]. `solve(rng, valid)` draws
// `sample_size` distinct indices into `valid` and returns the minimal solution, or nothing for a
// degenerate sample; `fit(indices)` is the least-squares solution on those correspondences. Result
// has T_a_b, inliers, inlier_rms, iterations, degenerate_samples and skipped_non_finite.
template <class Result, class Solve, class Fit>
Expected<Result> EstimateRansac(const FourDofRansacOptions& options, std::span<const Eigen::Vector3d> source_b,
                                std::span<const Eigen::Vector3d> target_a, size_t sample_size, const Solve& solve,
                                const Fit& fit) {
  CAIRN_RETURN_IF_ERROR(options.Validate());
  if (source_b.size() != target_a.size())
    return InvalidArgumentError("ransac: " + std::to_string(source_b.size()) + " source points but " +
                                std::to_string(target_a.size()) + " target points");
  Result result;
  std::vector<size_t> valid;
  valid.reserve(source_b.size());
  for (size_t i = 0; i < source_b.size(); ++i) {
    if (source_b[i].allFinite() && target_a[i].allFinite()) valid.push_back(i);
  }
  result.skipped_non_finite = source_b.size() - valid.size();
  const size_t needed = std::max(sample_size, static_cast<size_t>(std::max<int64_t>(0, options.min_inliers)));
  if (valid.size() < needed)
    return FailedPreconditionError("ransac: too few correspondences: " + std::to_string(valid.size()) +
                                   " finite (" + std::to_string(result.skipped_non_finite) +
                                   " non-finite skipped), need " + std::to_string(needed));

  const double threshold_sq = options.inlier_threshold * options.inlier_threshold;
  std::mt19937_64 rng(options.seed);
  RansacScore best;
  decltype(result.T_a_b) best_T = result.T_a_b;
  bool have_best = false;
  int64_t required = options.max_iterations;
  int64_t it = 0;
  for (; it < options.max_iterations && it < required; ++it) {
    const auto T = solve(rng, std::span<const size_t>(valid));
    if (!T) {
      ++result.degenerate_samples;
      continue;
    }
    const RansacScore s = EvaluateRansac(*T, source_b, target_a, valid, threshold_sq);
    if (!have_best || s.BetterThan(best)) {
      best = s;
      best_T = *T;
      have_best = true;
      required = RequiredSamples(s.inliers, valid.size(), sample_size, options.confidence, options.max_iterations);
    }
  }
  result.iterations = it;
  if (!have_best)
    return NotFoundError("ransac: no consensus: all " + std::to_string(it) + " samples were degenerate");
  if (best.inliers < needed)
    return NotFoundError("ransac: no consensus: the best of " + std::to_string(it) + " hypotheses has " +
                         std::to_string(best.inliers) + " inliers, need " + std::to_string(needed));

  CollectRansacInliers(best_T, source_b, target_a, valid, threshold_sq, &result.inliers);
  std::vector<size_t> refit_inliers;
  for (int64_t round = 0; round < options.refine_rounds; ++round) {
    const auto T = fit(std::span<const size_t>(result.inliers));
    if (!T) break;
    const RansacScore s = EvaluateRansac(*T, source_b, target_a, valid, threshold_sq);
    if (!s.BetterThan(best)) break;
    best = s;
    best_T = *T;
    CollectRansacInliers(best_T, source_b, target_a, valid, threshold_sq, &refit_inliers);
    const bool same = refit_inliers == result.inliers;
    result.inliers.swap(refit_inliers);
    if (same) break;
  }
  result.T_a_b = best_T;
  result.inlier_rms = std::sqrt(best.sum_sq / static_cast<double>(best.inliers));
  return result;
}

}  // namespace cairn
