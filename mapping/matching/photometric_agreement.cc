#include "mapping/matching/photometric_agreement.h"

#include <algorithm>
#include <cmath>

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

}  // namespace cairn
