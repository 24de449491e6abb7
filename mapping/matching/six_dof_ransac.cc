#include "mapping/matching/six_dof_ransac.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <string>

#include <Eigen/SVD>

#include "mapping/matching/ransac_core.h"

namespace cairn {
namespace {

// The rigid motion minimizing sum |R b_i + t - a_i|^2 (Kabsch: R from the SVD of the centred
// cross-covariance, a reflection turned into the nearest rotation); nothing when the centred
// points span less than a plane (a rotation about their line would be free).
std::optional<Eigen::Isometry3d> Kabsch(const Eigen::Vector3d* b, const Eigen::Vector3d* a, size_t n,
                                        const size_t* indices) {
  Eigen::Vector3d mean_a = Eigen::Vector3d::Zero(), mean_b = Eigen::Vector3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    const size_t i = indices != nullptr ? indices[k] : k;
    mean_a += a[i];
    mean_b += b[i];
  }
  mean_a /= static_cast<double>(n);
  mean_b /= static_cast<double>(n);
  Eigen::Matrix3d S = Eigen::Matrix3d::Zero();
  for (size_t k = 0; k < n; ++k) {
    const size_t i = indices != nullptr ? indices[k] : k;
    S.noalias() += (a[i] - mean_a) * (b[i] - mean_b).transpose();
  }
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(S, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Eigen::Vector3d sv = svd.singularValues();
  // Collinear (or coincident) points: the second singular value vanishes.
  if (!(sv(0) > 0.0) || !(sv(1) > 1e-9 * sv(0))) return std::nullopt;
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  if ((svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0) D(2, 2) = -1.0;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = svd.matrixU() * D * svd.matrixV().transpose();
  T.translation() = mean_a - T.linear() * mean_b;
  if (!T.matrix().allFinite()) return std::nullopt;
  return T;
}

// Distance of p from the line through q0 and q1 (q0 != q1).
double DistanceFromLine(const Eigen::Vector3d& p, const Eigen::Vector3d& q0, const Eigen::Vector3d& q1) {
  const Eigen::Vector3d d = (q1 - q0).normalized();
  return (p - q0).cross(d).norm();
}

}  // namespace

std::optional<Eigen::Isometry3d> SixDofRansac::SolveThreePoint(const Eigen::Vector3d (&source)[3],
                                                               const Eigen::Vector3d (&target)[3]) const {
  const double min_len = std::max(options_.min_horizontal_separation, 1e-9);
  const double tol = options_.max_pair_length_difference;
  for (int i = 0; i < 3; ++i) {
    const int j = (i + 1) % 3;
    const double len_b = (source[j] - source[i]).norm(), len_a = (target[j] - target[i]).norm();
    if (!(len_b >= min_len) || !(len_a >= min_len)) return std::nullopt;
    // A rigid motion keeps lengths: a sample that changes one holds a wrong correspondence.
    if (!(std::abs(len_a - len_b) <= tol)) return std::nullopt;
  }
  if (!(DistanceFromLine(source[2], source[0], source[1]) >= 0.5 * min_len) ||
      !(DistanceFromLine(target[2], target[0], target[1]) >= 0.5 * min_len))
    return std::nullopt;
  return Kabsch(source, target, 3, nullptr);
}

std::optional<Eigen::Isometry3d> SixDofRansac::FitLeastSquares(std::span<const Eigen::Vector3d> source_b,
                                                               std::span<const Eigen::Vector3d> target_a,
                                                               std::span<const size_t> indices) {
  if (indices.size() < 3) return std::nullopt;
  return Kabsch(source_b.data(), target_a.data(), indices.size(), indices.data());
}

Expected<SixDofRansacResult> SixDofRansac::Estimate(std::span<const Eigen::Vector3d> source_b,
                                                    std::span<const Eigen::Vector3d> target_a) const {
  const auto solve = [&](std::mt19937_64& rng, std::span<const size_t> valid) {
    // Three distinct indices, drawn one after the other (a fixed order whatever the compiler).
    size_t pick[3];
    pick[0] = DrawIndex(rng, valid.size());
    pick[1] = DrawIndex(rng, valid.size() - 1);
    if (pick[1] >= pick[0]) ++pick[1];
    pick[2] = DrawIndex(rng, valid.size() - 2);
    for (const size_t taken : {std::min(pick[0], pick[1]), std::max(pick[0], pick[1])}) {
      if (pick[2] >= taken) ++pick[2];
    }
    const Eigen::Vector3d source[3] = {source_b[valid[pick[0]]], source_b[valid[pick[1]]], source_b[valid[pick[2]]]};
    const Eigen::Vector3d target[3] = {target_a[valid[pick[0]]], target_a[valid[pick[1]]], target_a[valid[pick[2]]]};
    return SolveThreePoint(source, target);
  };
  const auto fit = [&](std::span<const size_t> indices) { return FitLeastSquares(source_b, target_a, indices); };
  return EstimateRansac<SixDofRansacResult>(options_, source_b, target_a, 3, solve, fit);
}

}  // namespace cairn
