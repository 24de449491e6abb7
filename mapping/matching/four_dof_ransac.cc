#include "mapping/matching/four_dof_ransac.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>

#include "mapping/matching/ransac_core.h"

namespace cairn {

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
  const auto solve = [&](std::mt19937_64& rng, std::span<const size_t> valid) {
    // Two distinct indices, drawn one after the other (a fixed order whatever the compiler).
    const size_t i = DrawIndex(rng, valid.size());
    size_t j = DrawIndex(rng, valid.size() - 1);
    if (j >= i) ++j;
    return SolveTwoPoint(source_b[valid[i]], source_b[valid[j]], target_a[valid[i]], target_a[valid[j]]);
  };
  const auto fit = [&](std::span<const size_t> indices) { return FitLeastSquares(source_b, target_a, indices); };
  return EstimateRansac<FourDofRansacResult>(options_, source_b, target_a, 2, solve, fit);
}

}  // namespace cairn
