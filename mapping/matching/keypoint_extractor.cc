#include "mapping/matching/keypoint_extractor.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace cairn {
namespace {

// Voxel indices packed 21 bits per axis around an offset: +-1e6 voxels reach 100 km at 0.1 m,
// far beyond any submap, and points beyond are counted as non-finite input.
constexpr int64_t kKeyBits = 21;
constexpr int64_t kKeyOffset = int64_t{1} << (kKeyBits - 1);
constexpr int64_t kKeyMax = (int64_t{1} << kKeyBits) - 1;

bool PackKey(const Eigen::Vector3f& p, double inv_voxel, uint64_t* key) {
  uint64_t packed = 0;
  for (int i = 0; i < 3; ++i) {
    const double v = std::floor(static_cast<double>(p[i]) * inv_voxel);
    if (!(v >= -static_cast<double>(kKeyOffset) && v < static_cast<double>(kKeyMax - kKeyOffset)))
      return false;
    packed |= static_cast<uint64_t>(static_cast<int64_t>(v) + kKeyOffset) << (kKeyBits * i);
  }
  *key = packed;
  return true;
}

}  // namespace

SubmapKeypoints KeypointExtractor::VoxelKeypoints(const std::vector<CloudPoint>& points) const {
  SubmapKeypoints out;
  const double inv_voxel = 1.0 / options_.voxel_size;
  std::vector<std::pair<uint64_t, uint32_t>> keyed;
  keyed.reserve(points.size() / 4);
  for (size_t i = 0; i < points.size(); ++i) {
    const CloudPoint& c = points[i];
    if (!c.p.allFinite()) {
      ++out.non_finite_points;
      continue;
    }
    if (!c.obstacle) continue;
    uint64_t key = 0;
    if (!PackKey(c.p, inv_voxel, &key)) {
      ++out.non_finite_points;
      continue;
    }
    keyed.emplace_back(key, static_cast<uint32_t>(i));
    ++out.obstacle_points;
  }
  // Sorting by key groups each voxel's points and makes the order independent of the input's.
  std::sort(keyed.begin(), keyed.end());
  for (size_t begin = 0; begin < keyed.size();) {
    size_t end = begin;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    while (end < keyed.size() && keyed[end].first == keyed[begin].first) {
      sum += points[keyed[end].second].p.cast<double>();
      ++end;
    }
    out.points.push_back((sum / static_cast<double>(end - begin)).cast<float>());
    begin = end;
  }
  out.voxel_keypoints = static_cast<int64_t>(out.points.size());
  return out;
}

double KeypointExtractor::KnownFraction(const octomap::OcTree& tree, const Eigen::Vector3f& centre) const {
  octomap::OcTreeKey ck;
  if (!tree.coordToKeyChecked(octomap::point3d(centre.x(), centre.y(), centre.z()), ck)) return 0.0;
  const double res = tree.getResolution();
  const double r = options_.support_radius;
  const double r2 = r * r;
  const int n = static_cast<int>(std::ceil(r / res)) + 1;
  int known = 0, total = 0;
  for (int dz = -n; dz <= n; ++dz) {
    for (int dy = -n; dy <= n; ++dy) {
      for (int dx = -n; dx <= n; ++dx) {
        const int kx = ck[0] + dx, ky = ck[1] + dy, kz = ck[2] + dz;
        if (kx < 0 || ky < 0 || kz < 0 || kx > 0xFFFF || ky > 0xFFFF || kz > 0xFFFF) continue;
        const octomap::OcTreeKey key(static_cast<uint16_t>(kx), static_cast<uint16_t>(ky),
                                     static_cast<uint16_t>(kz));
        const octomap::point3d c = tree.keyToCoord(key);
        const double ex = c.x() - centre.x(), ey = c.y() - centre.y(), ez = c.z() - centre.z();
        if (ex * ex + ey * ey + ez * ez > r2 && (dx | dy | dz) != 0) continue;
        ++total;
        // A pruned tree answers with the coarser node that covers the voxel: known as well.
        if (tree.search(key) != nullptr) ++known;
      }
    }
  }
  return static_cast<double>(known) / static_cast<double>(total);
}

SubmapKeypoints KeypointExtractor::Extract(const Submap& submap) const {
  SubmapKeypoints voxels = VoxelKeypoints(submap.points());
  SubmapKeypoints out;
  out.non_finite_points = voxels.non_finite_points;
  out.obstacle_points = voxels.obstacle_points;
  out.voxel_keypoints = voxels.voxel_keypoints;
  out.points.reserve(voxels.points.size());
  out.known_fraction.reserve(voxels.points.size());
  for (const Eigen::Vector3f& p : voxels.points) {
    const double known = KnownFraction(submap.tree(), p);
    if (known < options_.min_known_fraction) {
      ++out.dropped_unknown;
      continue;
    }
    out.points.push_back(p);
    out.known_fraction.push_back(static_cast<float>(known));
  }
  return out;
}

}  // namespace cairn
