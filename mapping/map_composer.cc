#include "mapping/map_composer.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "common/heap_bytes.h"
#include "mapping/occupancy_integrator.h"

namespace cairn {

MapComposer::MapComposer(const CompositionOptions& options, const SubmapOptions& submap)
    : options_(options), submap_options_(submap), cloud_(options.cloud_resolution, 1 << 20),
      occupancy_(1 << 20), open_cloud_(options.cloud_resolution, 1 << 16), open_occupancy_(1 << 16) {}

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
    resampler_.Resample(e.submap->tree(), e.submap->points(), e.pose_target, &e.cloud, &e.occupancy);
    e.pose_applied = e.pose_target;
    e.applied = true;
    Apply(e, +1);
    ++stats.rebuilt;
  }
  open_cloud_.Clear();
  open_occupancy_.Clear();
  if (open_ != nullptr) {
    // The open tree's inner nodes are stale (lazy updates), but only leaves are read.
    resampler_.Resample(open_->tree(), open_->cloud().Points(), open_pose_, &open_points_, &open_pairs_);
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
    if ((c.array().abs() >= kOctreeKeyOrigin).any()) return;  // beyond OctoMap's key range
    const octomap::OcTreeKey k(static_cast<uint16_t>(c.x() + kOctreeKeyOrigin), static_cast<uint16_t>(c.y() + kOctreeKeyOrigin),
                               static_cast<uint16_t>(c.z() + kOctreeKeyOrigin));
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

size_t MapComposer::memory_bytes() const {
  size_t n = cloud_.memory_bytes() + occupancy_.memory_bytes() + open_cloud_.memory_bytes() +
             open_occupancy_.memory_bytes() + HeapBytes(open_points_, open_pairs_);
  for (const auto& [ref, e] : entries_) {
    n += sizeof(e) + HeapBytes(e.cloud, e.occupancy);
  }
  return n;
}

size_t MapComposer::submap_bytes() const {
  size_t n = 0;
  for (const auto& [ref, e] : entries_) n += e.submap != nullptr ? e.submap->memory_bytes() : 0;
  return n;
}

}  // namespace cairn
