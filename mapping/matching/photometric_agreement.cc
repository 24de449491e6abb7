#include "mapping/matching/photometric_agreement.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

namespace cairn {

PhotometricAgreement::PhotometricAgreement(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                                           double voxel)
    : inverse_voxel_(static_cast<float>(1.0 / voxel)), cells_(std::min(cloud.size(), grey.size())) {
  const size_t n = std::min(cloud.size(), grey.size());
  for (size_t i = 0; i < n; ++i) {
    uint64_t key = 0;
    if (!std::isfinite(grey[i]) || !VoxelKey::Of(cloud[i].cast<float>(), inverse_voxel_, &key)) continue;
    Cell& c = cells_[key];
    c.sum += grey[i];
    ++c.count;
  }
}

PhotometricScore PhotometricAgreement::Score(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                                             const FourDofTransform& T_a_b) const {
  return Score(cloud, grey, T_a_b.ToIsometry());
}

PhotometricScore PhotometricAgreement::Score(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                                             const Eigen::Isometry3d& T) const {
  PhotometricScore out;
  const size_t n = std::min(cloud.size(), grey.size());
  // Sums about the first pair's values, so that the variances do not cancel catastrophically.
  double a0 = 0.0, b0 = 0.0, sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
  for (size_t i = 0; i < n; ++i) {
    uint64_t key = 0;
    if (!std::isfinite(grey[i]) || !VoxelKey::Of((T * cloud[i]).cast<float>(), inverse_voxel_, &key)) continue;
    const Cell* cell = cells_.Find(key);
    if (cell == nullptr) continue;
    double a = cell->sum / static_cast<double>(cell->count), b = grey[i];
    if (out.pairs == 0) {
      a0 = a;
      b0 = b;
    }
    a -= a0;
    b -= b0;
    ++out.pairs;
    sa += a;
    sb += b;
    saa += a * a;
    sbb += b * b;
    sab += a * b;
  }
  if (out.pairs < 2) return out;
  const double m = static_cast<double>(out.pairs);
  const double var_a = saa / m - (sa / m) * (sa / m), var_b = sbb / m - (sb / m) * (sb / m);
  // Grey levels are whole numbers (at most 8 bits): a spread below a hundredth of a level is none.
  if (!(var_a > 1e-4) || !(var_b > 1e-4)) return out;
  out.ncc = std::clamp((sab / m - (sa / m) * (sb / m)) / std::sqrt(var_a * var_b), -1.0, 1.0);
  return out;
}

FourDofTransform PhotometricAgreement::Refine(const std::vector<Eigen::Vector3d>& cloud,
                                              const std::vector<float>& grey, const FourDofTransform& start,
                                              double step_translation, double step_yaw, int max_scores,
                                              PhotometricScore* best) const {
  const auto Value = [](const PhotometricScore& s) { return std::isfinite(s.ncc) ? s.ncc : -2.0; };
  // Yaw turns B about the centre of the overlap (B's points that fall into A's voxels at the
  // start), not about B's origin: about the origin a yaw step also slides the overlap by its
  // distance times the step (0.1 m for 0.01 rad at 10 m), so x, y and yaw are coupled, and the
  // search along the axes zigzags down the diagonal valley until the scores run out (on a team
  // mission's submaps, 34 of 136 refinements did).
  const Eigen::Isometry3d T_start = start.ToIsometry();
  Eigen::Vector3d overlap_b = Eigen::Vector3d::Zero();  // in B, so that it moves with B
  size_t overlapping = 0;
  for (size_t i = 0; i < std::min(cloud.size(), grey.size()); ++i) {
    uint64_t key = 0;
    if (!std::isfinite(grey[i]) || !VoxelKey::Of((T_start * cloud[i]).cast<float>(), inverse_voxel_, &key) ||
        cells_.Find(key) == nullptr)
      continue;
    overlap_b += cloud[i];
    ++overlapping;
  }
  if (overlapping > 0) overlap_b /= static_cast<double>(overlapping);
  FourDofTransform at = start;
  PhotometricScore here = Score(cloud, grey, at);
  int scores = 1;
  double dt = step_translation, dyaw = step_yaw;
  const double min_dt = 0.1 * step_translation, min_dyaw = 0.1 * step_yaw;
  while (scores + 6 <= max_scores && (dt >= min_dt || dyaw >= min_dyaw)) {
    bool moved = false;
    static constexpr int kAxes[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
    FourDofTransform next = at;
    PhotometricScore next_score = here;
    const Eigen::Vector2d centre = (at.ToIsometry() * overlap_b).head<2>();
    for (const auto& axis : kAxes) {
      Eigen::Vector3d t = at.translation() + Eigen::Vector3d(axis[0] * dt, axis[1] * dt, 0.0);
      if (axis[2] != 0) t.head<2>() = centre + Eigen::Rotation2Dd(axis[2] * dyaw) * (t.head<2>() - centre);
      const FourDofTransform trial(t, at.yaw() + axis[2] * dyaw);
      const PhotometricScore s = Score(cloud, grey, trial);
      ++scores;
      if (Value(s) > Value(next_score)) {
        next = trial;
        next_score = s;
        moved = true;
      }
    }
    if (moved) {
      at = next;
      here = next_score;
    } else {
      dt *= 0.5;
      dyaw *= 0.5;
    }
  }
  if (best != nullptr) *best = here;
  return at;
}

}  // namespace cairn
