#include "mapping/matching/photometric_agreement.h"

#include <algorithm>
#include <cmath>

namespace cairn {

PhotometricAgreement::PhotometricAgreement(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                                           double voxel)
    : inverse_voxel_(1.0 / voxel) {
  const size_t n = std::min(cloud.size(), grey.size());
  cells_.reserve(n);
  for (size_t i = 0; i < n; ++i) {
    if (!cloud[i].allFinite() || !std::isfinite(grey[i])) continue;
    Cell& c = cells_[Key(cloud[i])];
    c.sum += grey[i];
    ++c.count;
  }
}

uint64_t PhotometricAgreement::Key(const Eigen::Vector3d& p) const {
  // 21 bits per axis: unique within +-52 km at 5 cm, far beyond a submap.
  const auto axis = [&](double v) { return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v * inverse_voxel_))) & 0x1fffff; };
  return axis(p.x()) | axis(p.y()) << 21 | axis(p.z()) << 42;
}

PhotometricScore PhotometricAgreement::Score(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& grey,
                                             const FourDofTransform& T_a_b, size_t stride) const {
  PhotometricScore out;
  const Eigen::Isometry3d T = T_a_b.ToIsometry();
  const size_t n = std::min(cloud.size(), grey.size());
  // Sums about the first pair's values, so that the variances do not cancel catastrophically.
  double a0 = 0.0, b0 = 0.0, sa = 0.0, sb = 0.0, saa = 0.0, sbb = 0.0, sab = 0.0;
  for (size_t i = 0; i < n; i += std::max<size_t>(stride, 1)) {
    if (!cloud[i].allFinite() || !std::isfinite(grey[i])) continue;
    const auto it = cells_.find(Key(T * cloud[i]));
    if (it == cells_.end()) continue;
    double a = it->second.sum / static_cast<double>(it->second.count), b = grey[i];
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
