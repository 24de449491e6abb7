#include "mapping/submap_resampler.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mapping/occupancy_integrator.h"

namespace cairn {
namespace {

// True when T maps the voxel grid onto itself (no rotation, translation a whole number of voxels),
// so every voxel lands exactly on one global voxel.
bool GridAligned(const Eigen::Isometry3d& T, double res) {
  if (!T.linear().isIdentity(1e-9)) return false;
  const Eigen::Vector3d k = T.translation() / res;
  return (k - k.array().round().matrix()).cwiseAbs().maxCoeff() < 1e-6;
}

}  // namespace

void SubmapResampler::Resample(const octomap::OcTree& tree, const std::vector<CloudPoint>& points,
                               const Eigen::Isometry3d& T_global_submap, std::vector<CloudPoint>* cloud,
                               std::vector<std::pair<uint64_t, float>>* occupancy) {
  const Eigen::Isometry3d& T = T_global_submap;
  const Eigen::Matrix3f R = T.linear().cast<float>();
  const Eigen::Vector3f t = T.translation().cast<float>();
  cloud->resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    (*cloud)[i] = points[i];
    (*cloud)[i].p = R * points[i].p + t;
  }
  // Occupancy: every finest voxel of every leaf is resampled onto the global grid. Off-grid poses
  // use 2x2x2 samples per voxel and average what lands in each global voxel, so a rotated grid
  // leaves no holes and counts no voxel twice.
  const double res = tree.getResolution();
  const float inv = static_cast<float>(1.0 / res);
  const bool aligned = GridAligned(T, res);
  // Gravity-aligned submaps differ by yaw only: voxel layers map onto layers, so 2 x 2 samples in
  // x-y suffice; other rotations need 2 x 2 x 2.
  const int samples = std::abs(T.linear()(2, 2) - 1.0) < 1e-9 ? 4 : 8;
  const Eigen::Vector3f offsets[8] = {
      {-0.25f, -0.25f, 0.0f},   {0.25f, -0.25f, 0.0f},   {-0.25f, 0.25f, 0.0f},   {0.25f, 0.25f, 0.0f},
      {-0.25f, -0.25f, -0.25f}, {0.25f, -0.25f, -0.25f}, {-0.25f, 0.25f, -0.25f}, {0.25f, 0.25f, -0.25f}};
  // Leaves first, for the bounding box of the moved tree.
  const int tree_depth = static_cast<int>(tree.getTreeDepth());
  leaves_.clear();
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(std::numeric_limits<int>::max()), hi = -lo;
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const octomap::OcTreeKey k = it.getIndexKey();  // the leaf's lowest finest voxel
    const int cells = 1 << (tree_depth - static_cast<int>(it.getDepth()));
    const Eigen::Vector3i a(k[0] - kOctreeKeyOrigin, k[1] - kOctreeKeyOrigin, k[2] - kOctreeKeyOrigin);
    leaves_.push_back({a, cells, it->getLogOdds(), tree.isNodeOccupied(*it)});
    lo = lo.cwiseMin(a);
    hi = hi.cwiseMax(a + Eigen::Vector3i::Constant(cells));
  }
  // Samples land in a dense grid over the moved box when it is small enough (every submap made
  // along a few metres is), which costs an index instead of a hash lookup per sample.
  resample_.Clear();
  bool dense = false;
  Eigen::Vector3i g0 = Eigen::Vector3i::Zero(), dims = Eigen::Vector3i::Zero();
  if (!leaves_.empty()) {
    Eigen::Vector3f bmin = Eigen::Vector3f::Constant(std::numeric_limits<float>::max()), bmax = -bmin;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3f corner((c & 1 ? hi.x() : lo.x()) * static_cast<float>(res),
                                   (c & 2 ? hi.y() : lo.y()) * static_cast<float>(res),
                                   (c & 4 ? hi.z() : lo.z()) * static_cast<float>(res));
      const Eigen::Vector3f g = R * corner + t;
      bmin = bmin.cwiseMin(g);
      bmax = bmax.cwiseMax(g);
    }
    const Eigen::Vector3f fmin = (bmin * inv).array().floor() - 2.0f, fmax = (bmax * inv).array().floor() + 2.0f;
    const Eigen::Vector3f extent = fmax - fmin + Eigen::Vector3f::Ones();
    constexpr double kMaxDenseCells = 1 << 23;
    if ((fmin.array() > -1e6f).all() && (fmax.array() < 1e6f).all() &&
        static_cast<double>(extent.x()) * extent.y() * extent.z() <= kMaxDenseCells) {
      dense = true;
      g0 = fmin.cast<int>();
      dims = extent.cast<int>();
      const size_t cells = static_cast<size_t>(dims.x()) * static_cast<size_t>(dims.y()) * static_cast<size_t>(dims.z());
      if (dense_.size() < cells) dense_.resize(cells);
      touched_.clear();
    }
  }
  // Sampling works in global voxel units (g = R c + t / res with c in source voxels): no scaling
  // per sample, and the rotated sample offsets and voxel steps are computed once.
  // VoxelKey::Floor rather than std::floor: the x86-64 baseline has no rounding instruction, and
  // the library call was the largest single cost of a full rebuild.
  constexpr float lim = static_cast<float>(VoxelKey::kOffset);
  const auto add = [&](const Eigen::Vector3f& g, float value, int32_t weight) {
    if (!(g.x() >= -lim && g.x() < lim && g.y() >= -lim && g.y() < lim && g.z() >= -lim && g.z() < lim)) return;
    const int32_t fx = VoxelKey::Floor(g.x()), fy = VoxelKey::Floor(g.y()), fz = VoxelKey::Floor(g.z());
    if (dense) {
      const int x = fx - g0.x(), y = fy - g0.y(), z = fz - g0.z();
      if (x >= 0 && y >= 0 && z >= 0 && x < dims.x() && y < dims.y() && z < dims.z()) {
        const uint32_t i = static_cast<uint32_t>((z * dims.y() + y) * dims.x() + x);
        Occ& o = dense_[i];
        if (o.n == 0) touched_.emplace_back(i, VoxelKey::Pack(fx, fy, fz));
        o.sum += static_cast<float>(weight) * value;
        o.n += weight;
        return;
      }
    }
    Occ& o = resample_[VoxelKey::Pack(fx, fy, fz)];
    o.sum += static_cast<float>(weight) * value;
    o.n += weight;
  };
  const Eigen::Vector3f tv = t * inv;
  const Eigen::Vector3f step_x = R.col(0), step_y = R.col(1), step_z = R.col(2);
  Eigen::Vector3f sample[8];
  const int n_samples = aligned ? 1 : samples;
  for (int si = 0; si < n_samples; ++si) {
    // The 8-sample set: the z = -1/4 layer above plus the same x-y pattern at z = +1/4.
    Eigen::Vector3f off = aligned ? Eigen::Vector3f::Zero() : offsets[si];
    if (samples == 8 && si < 4) off.z() = 0.25f;
    sample[si] = R * off;
  }
  // Where the points of each finest voxel lie (an aligned pose moves every voxel exactly).
  centroids_.Clear();
  if (!aligned) {
    for (const CloudPoint& c : points) {
      const Eigen::Vector3f s = c.p * inv;
      const int32_t x = VoxelKey::Floor(s.x()), y = VoxelKey::Floor(s.y()), z = VoxelKey::Floor(s.z());
      if (!VoxelKey::InRange(x) || !VoxelKey::InRange(y) || !VoxelKey::InRange(z)) continue;
      PointSum& ps = centroids_[VoxelKey::Pack(x, y, z)];
      ps.sum += s - Eigen::Vector3f(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
      ++ps.n;
    }
  }
  for (const Leaf& leaf : leaves_) {
    const float value = leaf.value;
    const int cells = leaf.cells;
    Eigen::Vector3f inside = Eigen::Vector3f::Constant(0.5f);
    int32_t weight = 1;
    if (cells == 1 && leaf.occupied && !centroids_.empty()) {
      if (const PointSum* ps = centroids_.Find(VoxelKey::Pack(leaf.min.x(), leaf.min.y(), leaf.min.z()))) {
        inside = ps->sum / static_cast<float>(ps->n);
        // Its global voxel holds the surface: free space of a neighbour that lands there too must
        // not average it away (occupied wins over free, as within an image).
        weight = kSurfaceWeight;
      }
    }
    const Eigen::Vector3f base = R * (leaf.min.cast<float>() + inside) + tv;
    for (int dz = 0; dz < cells; ++dz) {
      const Eigen::Vector3f pz = base + static_cast<float>(dz) * step_z;
      for (int dy = 0; dy < cells; ++dy) {
        const Eigen::Vector3f py = pz + static_cast<float>(dy) * step_y;
        for (int dx = 0; dx < cells; ++dx) {
          const Eigen::Vector3f g = py + static_cast<float>(dx) * step_x;
          for (int si = 0; si < n_samples; ++si) add(g + sample[si], value, weight);
        }
      }
    }
  }
  occupancy->clear();
  occupancy->reserve(resample_.size() + touched_.size());
  // Mostly empty (everything in the dense grid), and a scan of its slots costs 2 MB of reads.
  if (!resample_.empty()) {
    resample_.ForEach([&](uint64_t key, const Occ& o) { occupancy->emplace_back(key, o.sum / static_cast<float>(o.n)); });
  }
  if (dense) {
    for (const auto& [i, key] : touched_) {
      Occ& o = dense_[i];
      occupancy->emplace_back(key, o.sum / static_cast<float>(o.n));
      o = Occ{};
    }
    touched_.clear();
  }
}

}  // namespace cairn
