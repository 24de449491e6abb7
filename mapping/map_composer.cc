#include "mapping/map_composer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

namespace cairn {
namespace {

constexpr int kTreeMaxKey = 32768;  // OctoMap's key of coordinate 0 at depth 16

// True when T maps the voxel grid onto itself (no rotation, translation a whole number of voxels),
// so every voxel lands exactly on one global voxel.
bool GridAligned(const Eigen::Isometry3d& T, double res) {
  if (!T.linear().isIdentity(1e-9)) return false;
  const Eigen::Vector3d k = T.translation() / res;
  return (k - k.array().round().matrix()).cwiseAbs().maxCoeff() < 1e-6;
}

}  // namespace

MapComposer::MapComposer(const CompositionOptions& options, const SubmapOptions& submap)
    : options_(options), submap_options_(submap), cloud_(options.cloud_resolution, 1 << 20),
      occupancy_(1 << 20), open_cloud_(options.cloud_resolution, 1 << 16), open_occupancy_(1 << 16),
      resample_(1 << 16) {}

float MapComposer::Clamp(float v) const {
  return std::clamp(v, static_cast<float>(submap_options_.log_odds_min), static_cast<float>(submap_options_.log_odds_max));
}

Status MapComposer::SetSubmap(std::shared_ptr<const Submap> submap, const Eigen::Isometry3d& T) {
  if (submap == nullptr) return InvalidArgumentError("SetSubmap: null submap");
  if (std::abs(submap->tree().getResolution() - submap_options_.octree_resolution) > 1e-9) {
    return InvalidArgumentError("submap " + submap->metadata().robot + "/" + std::to_string(submap->metadata().id) +
                                " has octree resolution " + std::to_string(submap->tree().getResolution()) +
                                ", composition uses " + std::to_string(submap_options_.octree_resolution));
  }
  if (!T.matrix().allFinite()) return InvalidArgumentError("SetSubmap: pose is not finite");
  const SubmapRef ref{submap->metadata().robot, submap->metadata().id};
  Entry& e = entries_[ref];
  if (e.submap != nullptr && e.submap != submap && e.applied) {
    Apply(e, -1);  // replaced content: take the old one out now
    e.applied = false;
  }
  e.submap = std::move(submap);
  e.pose_target = T;
  return Status::Ok();
}

Status MapComposer::SetPose(const SubmapRef& ref, const Eigen::Isometry3d& T) {
  auto it = entries_.find(ref);
  if (it == entries_.end()) return NotFoundError("no submap " + ref.robot + "/" + std::to_string(ref.id));
  if (!T.matrix().allFinite()) return InvalidArgumentError("SetPose: pose is not finite");
  it->second.pose_target = T;
  return Status::Ok();
}

void MapComposer::RemoveSubmap(const SubmapRef& ref) {
  auto it = entries_.find(ref);
  if (it == entries_.end()) return;
  if (it->second.applied) Apply(it->second, -1);
  entries_.erase(it);
}

void MapComposer::SetOpenSubmap(const OpenSubmap* open, const Eigen::Isometry3d& T) {
  open_ = open;
  open_pose_ = T;
}

bool MapComposer::Moved(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) const {
  const Eigen::Isometry3d d = a.inverse() * b;
  const double angle = Eigen::AngleAxisd(d.linear()).angle() * 180.0 / std::numbers::pi;
  return d.translation().norm() > options_.rebuild_translation || angle > options_.rebuild_rotation_deg;
}

void MapComposer::Contribute(const octomap::OcTree& tree, const std::vector<CloudPoint>& points,
                             const Eigen::Isometry3d& T, std::vector<CloudPoint>* cloud,
                             std::vector<std::pair<uint64_t, float>>* occupancy) {
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
    const Eigen::Vector3i a(k[0] - kTreeMaxKey, k[1] - kTreeMaxKey, k[2] - kTreeMaxKey);
    leaves_.push_back({a, cells, it->getLogOdds()});
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
  const auto add = [&](const Eigen::Vector3f& g, float value) {
    const Eigen::Vector3f f = g.array().floor();
    if (dense) {
      const int x = static_cast<int>(f.x()) - g0.x(), y = static_cast<int>(f.y()) - g0.y(), z = static_cast<int>(f.z()) - g0.z();
      if (x >= 0 && y >= 0 && z >= 0 && x < dims.x() && y < dims.y() && z < dims.z()) {
        const uint32_t i = static_cast<uint32_t>((z * dims.y() + y) * dims.x() + x);
        Occ& o = dense_[i];
        if (o.n == 0) touched_.push_back(i);
        o.sum += value;
        ++o.n;
        return;
      }
    }
    uint64_t key;
    if (!VoxelKey::Of(f, 1.0f, &key)) return;
    Occ& o = resample_[key];
    o.sum += value;
    ++o.n;
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
  for (const Leaf& leaf : leaves_) {
    const float value = leaf.value;
    const int cells = leaf.cells;
    const Eigen::Vector3f base = R * (leaf.min.cast<float>() + Eigen::Vector3f::Constant(0.5f)) + tv;
    for (int dz = 0; dz < cells; ++dz) {
      const Eigen::Vector3f pz = base + static_cast<float>(dz) * step_z;
      for (int dy = 0; dy < cells; ++dy) {
        const Eigen::Vector3f py = pz + static_cast<float>(dy) * step_y;
        for (int dx = 0; dx < cells; ++dx) {
          const Eigen::Vector3f g = py + static_cast<float>(dx) * step_x;
          for (int si = 0; si < n_samples; ++si) add(g + sample[si], value);
        }
      }
    }
  }
  occupancy->clear();
  occupancy->reserve(resample_.size() + touched_.size());
  resample_.ForEach([&](uint64_t key, const Occ& o) { occupancy->emplace_back(key, o.sum / static_cast<float>(o.n)); });
  if (dense) {
    for (const uint32_t i : touched_) {
      Occ& o = dense_[i];
      const int x = static_cast<int>(i % static_cast<uint32_t>(dims.x()));
      const int y = static_cast<int>(i / static_cast<uint32_t>(dims.x()) % static_cast<uint32_t>(dims.y()));
      const int z = static_cast<int>(i / (static_cast<uint32_t>(dims.x()) * static_cast<uint32_t>(dims.y())));
      occupancy->emplace_back(VoxelKey::Pack(g0.x() + x, g0.y() + y, g0.z() + z), o.sum / static_cast<float>(o.n));
      o = Occ{};
    }
    touched_.clear();
  }
}

void MapComposer::Apply(const Entry& e, int sign) {
  cloud_.AddAll(e.cloud, sign);
  const float s = static_cast<float>(sign);
  constexpr size_t kAhead = 16;
  for (size_t i = 0; i < e.occupancy.size(); ++i) {
    if (i + kAhead < e.occupancy.size()) occupancy_.Prefetch(e.occupancy[i + kAhead].first);
    const auto& [key, value] = e.occupancy[i];
    Occ& o = occupancy_[key];
    known_voxels_ += (o.n == 0) - (o.n + sign == 0);
    o.sum += s * value;
    o.n += sign;
    if (o.n == 0) o.sum = 0.0f;  // no rounding residue on emptied voxels
  }
}

CompositionStats MapComposer::Update() {
  CompositionStats stats;
  for (auto& [ref, e] : entries_) {
    if (e.applied && !Moved(e.pose_applied, e.pose_target)) {
      ++stats.cached;
      continue;
    }
    if (e.applied) Apply(e, -1);
    Contribute(e.submap->tree(), e.submap->points(), e.pose_target, &e.cloud, &e.occupancy);
    e.pose_applied = e.pose_target;
    e.applied = true;
    Apply(e, +1);
    ++stats.rebuilt;
  }
  open_cloud_.Clear();
  open_occupancy_.Clear();
  if (open_ != nullptr) {
    // The open tree's inner nodes are stale (lazy updates), but only leaves are read.
    Contribute(open_->tree(), open_->cloud().Points(), open_pose_, &open_points_, &open_pairs_);
    open_cloud_.AddAll(open_points_, 1);
    for (const auto& [key, value] : open_pairs_) open_occupancy_[key] = value;
  }
  // Counted as contributions come and go: a scan of the global table would cost more than an
  // incremental update itself.
  stats.voxels = known_voxels_;
  return stats;
}

CompositionStats MapComposer::Rebuild() {
  cloud_.Clear();
  occupancy_.Clear();
  known_voxels_ = 0;
  for (auto& [ref, e] : entries_) e.applied = false;
  return Update();
}

std::vector<CloudPoint> MapComposer::Cloud() const { return cloud_.MergedPoints(open_cloud_); }

float MapComposer::LogOdds(const Eigen::Vector3d& p) const {
  uint64_t key;
  if (!VoxelKey::Of(p.cast<float>(), static_cast<float>(1.0 / submap_options_.octree_resolution), &key)) {
    return std::numeric_limits<float>::quiet_NaN();
  }
  const Occ* o = occupancy_.Find(key);
  const float* open = open_occupancy_.Find(key);
  if ((o == nullptr || o->n == 0) && open == nullptr) return std::numeric_limits<float>::quiet_NaN();
  return Clamp((o != nullptr && o->n > 0 ? o->sum : 0.0f) + (open != nullptr ? *open : 0.0f));
}

std::unique_ptr<octomap::OcTree> MapComposer::Octree() const {
  auto tree = MakeOccupancyTree(submap_options_);
  const auto put = [&](uint64_t key, float value) {
    const Eigen::Vector3i c = VoxelKey::Unpack(key);
    if ((c.array().abs() >= kTreeMaxKey).any()) return;  // beyond OctoMap's key range
    const octomap::OcTreeKey k(static_cast<uint16_t>(c.x() + kTreeMaxKey), static_cast<uint16_t>(c.y() + kTreeMaxKey),
                               static_cast<uint16_t>(c.z() + kTreeMaxKey));
    tree->setNodeValue(k, Clamp(value), true);
  };
  occupancy_.ForEach([&](uint64_t key, const Occ& o) {
    if (o.n == 0) return;
    const float* open = open_occupancy_.Find(key);
    put(key, o.sum + (open != nullptr ? *open : 0.0f));
  });
  open_occupancy_.ForEach([&](uint64_t key, float v) {
    const Occ* o = occupancy_.Find(key);
    if (o == nullptr || o->n == 0) put(key, v);
  });
  tree->updateInnerOccupancy();
  tree->prune();
  return tree;
}

}  // namespace cairn
