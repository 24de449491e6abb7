#include "mapping/voxel_cloud.h"

#include <algorithm>
#include <cmath>

namespace cairn {

VoxelCloud::VoxelCloud(double resolution, size_t expected_voxels)
    : res_(resolution),
      inv_res_(static_cast<float>(1.0 / resolution)),
      voxels_(expected_voxels),
      pending_(size_t{1} << kPendingBits) {}

size_t VoxelCloud::memory_bytes() const {
  return voxels_.memory_bytes() + keys_.capacity() * sizeof(uint64_t) + pending_.capacity() * sizeof(Pending);
}

size_t VoxelCloud::size() const {
  size_t n = 0;
  voxels_.ForEach([&](uint64_t, const Accum& a) { n += a.n > 0; });
  return n;
}

bool VoxelCloud::Add(const Eigen::Vector3f& p, uint8_t r, uint8_t g, uint8_t b, bool obstacle, int32_t weight) {
  uint64_t key;
  if (!VoxelKey::Of(p, inv_res_, &key)) return false;
  CloudPoint c;
  c.p = p;
  c.r = r;
  c.g = g;
  c.b = b;
  c.obstacle = obstacle;
  AddKeyed(key, c, weight);
  return true;
}

void VoxelCloud::AddKeyed(uint64_t key, const CloudPoint& c, int32_t weight) {
  const Eigen::Vector3f corner = VoxelKey::Unpack(key).cast<float>() * static_cast<float>(res_);
  Accum& a = voxels_[key];
  const float w = static_cast<float>(weight);
  a.sx += w * (c.p.x() - corner.x());
  a.sy += w * (c.p.y() - corner.y());
  a.sz += w * (c.p.z() - corner.z());
  a.n += weight;
  a.sr += weight * c.r;
  a.sg += weight * c.g;
  a.sb += weight * c.b;
  a.obstacles += c.obstacle ? weight : 0;
}

void VoxelCloud::AddAll(const std::vector<CloudPoint>& points, int32_t weight) {
  keys_.resize(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    if (!VoxelKey::Of(points[i].p, inv_res_, &keys_[i])) keys_[i] = VoxelKey::kEmpty;
  }
  constexpr size_t kAhead = 16;
  for (size_t i = 0; i < points.size(); ++i) {
    if (i + kAhead < points.size() && keys_[i + kAhead] != VoxelKey::kEmpty) voxels_.Prefetch(keys_[i + kAhead]);
    if (keys_[i] != VoxelKey::kEmpty) AddKeyed(keys_[i], points[i], weight);
  }
}

size_t VoxelCloud::AddBatch(const std::vector<Eigen::Vector3f>& p, const std::vector<uint8_t>& gray,
                            const std::vector<uint8_t>& obstacle, Cells* cells) {
  for (Pending& e : pending_) e.key = VoxelKey::kEmpty;
  const auto flush = [&](const Pending& e) {
    voxels_[e.key].Merge(e.sum);
    if (cells != nullptr && e.interior) cells->interior.push_back(e.key);
  };
  size_t dropped = 0;
  constexpr float lim = static_cast<float>(VoxelKey::kOffset);
  for (size_t i = 0; i < p.size(); ++i) {
    // VoxelKey::Of, keeping the scaled coordinates for the face test.
    const float sx = p[i].x() * inv_res_, sy = p[i].y() * inv_res_, sz = p[i].z() * inv_res_;
    if (!(sx >= -lim && sx < lim && sy >= -lim && sy < lim && sz >= -lim && sz < lim)) {
      ++dropped;
      continue;
    }
    const int32_t kx = VoxelKey::Floor(sx), ky = VoxelKey::Floor(sy), kz = VoxelKey::Floor(sz);
    const bool on_face = static_cast<float>(kx) == sx || static_cast<float>(ky) == sy || static_cast<float>(kz) == sz;
    const uint64_t key = VoxelKey::Pack(kx, ky, kz);
    Pending& e = pending_[VoxelKey::Slot(key, kPendingBits)];
    if (e.key != key) {
      if (e.key != VoxelKey::kEmpty) flush(e);
      e.key = key;
      e.sum = Accum{};
      e.corner = Eigen::Vector3f(static_cast<float>(kx), static_cast<float>(ky), static_cast<float>(kz)) * static_cast<float>(res_);
      e.interior = false;
    }
    e.interior = e.interior || !on_face;
    if (cells != nullptr && on_face) cells->on_face.push_back(static_cast<uint32_t>(i));
    const Eigen::Vector3f d = p[i] - e.corner;
    e.sum.sx += d.x();
    e.sum.sy += d.y();
    e.sum.sz += d.z();
    ++e.sum.n;
    e.sum.sr += gray[i];
    e.sum.sg += gray[i];
    e.sum.sb += gray[i];
    e.sum.obstacles += obstacle[i] != 0;
  }
  for (const Pending& e : pending_) {
    if (e.key != VoxelKey::kEmpty) flush(e);
  }
  return dropped;
}

CloudPoint VoxelCloud::Centroid(uint64_t key, const Accum& a) const {
  const float inv_n = 1.0f / static_cast<float>(a.n);
  const float res = static_cast<float>(res_);
  const Eigen::Vector3f corner = VoxelKey::Unpack(key).cast<float>() * res;
  // Keep the centroid inside its voxel despite float rounding of the sums.
  const auto in = [&](float s) { return std::clamp(s * inv_n, 0.0f, res * 0.999f); };
  CloudPoint c;
  c.p = corner + Eigen::Vector3f(in(a.sx), in(a.sy), in(a.sz));
  c.r = static_cast<uint8_t>((a.sr + a.n / 2) / a.n);
  c.g = static_cast<uint8_t>((a.sg + a.n / 2) / a.n);
  c.b = static_cast<uint8_t>((a.sb + a.n / 2) / a.n);
  c.obstacle = a.obstacles > 0;
  return c;
}

std::vector<CloudPoint> VoxelCloud::Points() const {
  std::vector<CloudPoint> out;
  out.reserve(voxels_.size());
  ForEachPoint([&](const CloudPoint& c) { out.push_back(c); });
  return out;
}

std::vector<CloudPoint> VoxelCloud::MergedPoints(const VoxelCloud& other) const {
  std::vector<CloudPoint> out;
  out.reserve(voxels_.size() + other.voxels_.size());
  voxels_.ForEach([&](uint64_t key, const Accum& a) {
    Accum m = a;
    if (const Accum* o = other.voxels_.Find(key)) m.Merge(*o);
    if (m.n > 0) out.push_back(Centroid(key, m));
  });
  other.voxels_.ForEach([&](uint64_t key, const Accum& o) {
    if (o.n > 0 && voxels_.Find(key) == nullptr) out.push_back(Centroid(key, o));
  });
  return out;
}

}  // namespace cairn
