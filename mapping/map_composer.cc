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
  resample_.Clear();
  const int tree_depth = static_cast<int>(tree.getTreeDepth());
  for (auto it = tree.begin_leafs(), end = tree.end_leafs(); it != end; ++it) {
    const float value = it->getLogOdds();
    const int cells = 1 << (tree_depth - static_cast<int>(it.getDepth()));
    // Key of the leaf's lowest finest voxel.
    const octomap::OcTreeKey k = it.getIndexKey();
    for (int dz = 0; dz < cells; ++dz) {
      for (int dy = 0; dy < cells; ++dy) {
        for (int dx = 0; dx < cells; ++dx) {
          const Eigen::Vector3f c((static_cast<int>(k[0]) + dx - kTreeMaxKey + 0.5f) * static_cast<float>(res),
                                  (static_cast<int>(k[1]) + dy - kTreeMaxKey + 0.5f) * static_cast<float>(res),
                                  (static_cast<int>(k[2]) + dz - kTreeMaxKey + 0.5f) * static_cast<float>(res));
          const Eigen::Vector3f g = R * c + t;
          uint64_t key;
          if (aligned) {
            if (VoxelKey::Of(g, inv, &key)) {
              Occ& o = resample_[key];
              o.sum += value;
              ++o.n;
            }
            continue;
          }
          for (int si = 0; si < samples; ++si) {
            // The 8-sample set: the z = -1/4 layer above plus the same x-y pattern at z = +1/4.
            Eigen::Vector3f off = offsets[si];
            if (samples == 8 && si < 4) off.z() = 0.25f;
            if (!VoxelKey::Of(g + R * (off * static_cast<float>(res)), inv, &key)) continue;
            Occ& o = resample_[key];
            o.sum += value;
            ++o.n;
          }
        }
      }
    }
  }
  occupancy->clear();
  occupancy->reserve(resample_.size());
  resample_.ForEach([&](uint64_t key, const Occ& o) { occupancy->emplace_back(key, o.sum / static_cast<float>(o.n)); });
}

void MapComposer::Apply(const Entry& e, int sign) {
  for (const CloudPoint& p : e.cloud) cloud_.Add(p, sign);
  const float s = static_cast<float>(sign);
  for (const auto& [key, value] : e.occupancy) {
    Occ& o = occupancy_[key];
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
    for (const CloudPoint& p : open_points_) open_cloud_.Add(p);
    for (const auto& [key, value] : open_pairs_) open_occupancy_[key] = value;
  }
  occupancy_.ForEach([&](uint64_t, const Occ& o) { stats.voxels += o.n > 0; });
  return stats;
}

CompositionStats MapComposer::Rebuild() {
  cloud_.Clear();
  occupancy_.Clear();
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
