#include "mapping/occupancy_integrator.h"

#include <bit>
#include <cmath>

namespace cairn {
namespace {
uint64_t PackOctoKey(const octomap::OcTreeKey& k) { return VoxelKey::Pack(k[0], k[1], k[2]); }


// OcTree::updateNode(key, occupied, lazy) for every key, with the same result (including its
// early abort on saturated nodes), but without its two descents from the root per key: the keys
// come in spatially coherent order (along rays, along image rows), so the path of the previous
// key is reused down to the deepest node both share.
void UpdateLeaves(octomap::OcTree* tree, const std::vector<octomap::OcTreeKey>& keys, bool occupied) {
  if (keys.empty()) return;
  const float update = occupied ? tree->getProbHitLog() : tree->getProbMissLog();
  const float lo = tree->getClampingThresMinLog(), hi = tree->getClampingThresMaxLog();
  const auto saturated = [&](const octomap::OcTreeNode* n) {
    return update >= 0.0f ? n->getLogOdds() >= hi : n->getLogOdds() <= lo;
  };
  size_t first = 0;
  if (tree->getRoot() == nullptr) {
    // The root can only be made through the tree's own update.
    tree->updateNode(keys[0], update, true);
    first = 1;
  }
  constexpr int kDepth = 16;
  // path[d]: the node at depth d on the previous key's path; valid up to `valid`.
  octomap::OcTreeNode* path[kDepth + 1];
  path[0] = tree->getRoot();
  int valid = 0;
  octomap::OcTreeKey prev;
  for (size_t i = first; i < keys.size(); ++i) {
    const octomap::OcTreeKey& key = keys[i];
    int d = 0;  // deepest depth shared with the previous key's valid path
    if (valid > 0) {
      const unsigned diff = static_cast<unsigned>((key[0] ^ prev[0]) | (key[1] ^ prev[1]) | (key[2] ^ prev[2]));
      d = std::min(valid, kDepth - static_cast<int>(std::bit_width(diff)));
    }
    prev = key;
    octomap::OcTreeNode* node = path[d];
    bool skip = false;
    bool created = false;
    for (; d < kDepth; ++d) {
      const unsigned pos = octomap::computeChildIdx(key, kDepth - 1 - d);
      if (!tree->nodeChildExists(node, pos)) {
        if (!created && !tree->nodeHasChildren(node)) {
          // A pruned leaf standing for the whole subtree: OctoMap leaves it alone when the update
          // cannot change it, and expands it otherwise.
          if (saturated(node)) {
            skip = true;
            break;
          }
          tree->expandNode(node);
        } else {
          tree->createNodeChild(node, pos);
          created = true;
        }
      }
      node = tree->getNodeChild(node, pos);
      path[d + 1] = node;
    }
    valid = d;
    if (skip || saturated(node)) continue;
    tree->updateNodeLogOdds(node, update);
  }
}

}  // namespace

std::unique_ptr<octomap::OcTree> MakeOccupancyTree(const SubmapOptions& o) {
  auto tree = std::make_unique<octomap::OcTree>(o.octree_resolution);
  tree->setProbHit(octomap::probability(static_cast<float>(o.log_odds_hit)));
  tree->setProbMiss(octomap::probability(static_cast<float>(o.log_odds_miss)));
  tree->setClampingThresMin(octomap::probability(static_cast<float>(o.log_odds_min)));
  tree->setClampingThresMax(octomap::probability(static_cast<float>(o.log_odds_max)));
  return tree;
}

OccupancyIntegrator::OccupancyIntegrator(double resolution, double max_distance) {
  side_ = 2 * static_cast<int>(std::ceil(max_distance / resolution)) + 4;
  stamps_.assign(static_cast<size_t>(side_) * static_cast<size_t>(side_) * static_cast<size_t>(side_), 0);
}

uint32_t& OccupancyIntegrator::Stamp(const octomap::OcTreeKey& k) {
  const int h = side_ / 2;
  const int x = k[0] - centre_[0] + h, y = k[1] - centre_[1] + h, z = k[2] - centre_[2] + h;
  if (x >= 0 && y >= 0 && z >= 0 && x < side_ && y < side_ && z < side_) {
    return stamps_[(static_cast<size_t>(z) * static_cast<size_t>(side_) + static_cast<size_t>(y)) * static_cast<size_t>(side_) + static_cast<size_t>(x)];
  }
  return overflow_[PackOctoKey(k)];
}

bool OccupancyIntegrator::Begin(const CameraPoints& pts, octomap::OcTree* tree) {
  // Stamps: generation g marks "free this image", g + 1 "occupied this image"; older values are
  // stale. On wrap-around everything is reset once.
  if (generation_ >= 0xFFFFFFF0u) {
    std::fill(stamps_.begin(), stamps_.end(), 0u);
    overflow_.Clear();
    generation_ = 0;
  }
  generation_ += 2;
  const Eigen::Vector3d o = pts.T_local_cam.translation();
  origin_ = octomap::point3d(static_cast<float>(o.x()), static_cast<float>(o.y()), static_cast<float>(o.z()));
  if (!tree->coordToKeyChecked(origin_, centre_)) return false;
  overflow_.Clear();
  occupied_.clear();
  free_.clear();
  factor_ = 1.0 / tree->getResolution();
  // Most points fall into a voxel an earlier point of the image already marked: neighbouring
  // pixels of a row share it, and the rows above left it. The image's marks are remembered in a
  // small direct-mapped set (a miss only costs the exact test through the stamps), because a
  // stamp lookup in the large cube misses the CPU caches.
  std::fill(recent_.begin(), recent_.end(), kNoKey);
  return true;
}

void OccupancyIntegrator::MarkOccupied(int kx, int ky, int kz) {
  const uint64_t packed = static_cast<uint64_t>(kx) | static_cast<uint64_t>(ky) << 16 | static_cast<uint64_t>(kz) << 32;
  uint64_t& seen = recent_[VoxelKey::Slot(packed, kRecentBits)];
  if (seen == packed) return;
  seen = packed;
  const octomap::OcTreeKey key(static_cast<uint16_t>(kx), static_cast<uint16_t>(ky), static_cast<uint16_t>(kz));
  uint32_t& s = Stamp(key);
  if (s != generation_ + 1) {
    s = generation_ + 1;
    occupied_.push_back(key);
  }
}

void OccupancyIntegrator::MarkPoint(const Eigen::Vector3f& p) {
  // OcTreeBaseImpl::coordToKeyChecked: floor(resolution_factor * coordinate) + 2^15, in range.
  int k[3];
  bool inside = true;
  for (int a = 0; a < 3; ++a) {
    const double s = factor_ * static_cast<double>(p[a]);
    inside = inside && s >= -kOctreeKeyOrigin && s < kOctreeKeyOrigin;
    k[a] = (inside ? VoxelKey::Floor(s) : 0) + kOctreeKeyOrigin;
  }
  if (inside) MarkOccupied(k[0], k[1], k[2]);
}

OccupancyUpdateStats OccupancyIntegrator::Integrate(const CameraPoints& pts, octomap::OcTree* tree) {
  if (!Begin(pts, tree)) return {};
  for (const Eigen::Vector3f& p : pts.p_local) MarkPoint(p);
  return CastAndUpdate(pts, tree);
}

// A point strictly inside cloud cell k (k < s < k + 1 for s = fl32(p * c) on every axis) has
// k < p * c < k + 1 exactly, since rounding is monotonic and k, k + 1 are floats (|k| < 2^24).
// With c = 2 f exactly, p * f lies in (k / 2, (k + 1) / 2), an interval holding no integer in its
// inside, and its double rounding cannot reach the integer (k + 1) / 2 (that would take a float
// rounding of p * c to k + 1): the tree's key is floor(k / 2), the same for all such points.
OccupancyUpdateStats OccupancyIntegrator::IntegrateCells(const CameraPoints& pts, const VoxelCloud::Cells& cells,
                                                         float cloud_inv_resolution, octomap::OcTree* tree) {
  if (static_cast<double>(cloud_inv_resolution) != 2.0 * (1.0 / tree->getResolution())) return Integrate(pts, tree);
  if (!Begin(pts, tree)) return {};
  for (const uint64_t cell : cells.interior) {
    const Eigen::Vector3i c = VoxelKey::Unpack(cell);
    const int kx = (c.x() >> 1) + kOctreeKeyOrigin, ky = (c.y() >> 1) + kOctreeKeyOrigin, kz = (c.z() >> 1) + kOctreeKeyOrigin;
    constexpr int kKeys = 2 * kOctreeKeyOrigin;
    if (kx >= 0 && ky >= 0 && kz >= 0 && kx < kKeys && ky < kKeys && kz < kKeys) MarkOccupied(kx, ky, kz);
  }
  for (const uint32_t i : cells.on_face) MarkPoint(pts.p_local[i]);
  return CastAndUpdate(pts, tree);
}

OccupancyUpdateStats OccupancyIntegrator::CastAndUpdate(const CameraPoints& pts, octomap::OcTree* tree) {
  OccupancyUpdateStats stats;
  const uint32_t kFree = generation_;
  const octomap::point3d origin = origin_;
  octomap::OcTreeKey key;
  const auto cast = [&](const octomap::point3d& end) {
    ++stats.rays;
    if (!tree->computeRayKeys(origin, end, ray_)) return;
    for (const octomap::OcTreeKey& k : ray_) {
      uint32_t& s = Stamp(k);
      if (s < kFree) {
        s = kFree;
        free_.push_back(k);
      }
    }
  };
  for (const octomap::OcTreeKey& k : occupied_) cast(tree->keyToCoord(k));
  far_seen_.Clear();
  for (const Eigen::Vector3f& p : pts.far_local) {
    if (!tree->coordToKeyChecked(octomap::point3d(p.x(), p.y(), p.z()), key)) continue;
    uint8_t& seen = far_seen_[PackOctoKey(key)];
    if (seen) continue;
    seen = 1;
    cast(tree->keyToCoord(key));
  }
  UpdateLeaves(tree, free_, false);
  UpdateLeaves(tree, occupied_, true);
  stats.occupied = static_cast<int64_t>(occupied_.size());
  stats.free = static_cast<int64_t>(free_.size());
  return stats;
}

}  // namespace cairn
