#pragma once
// Point cloud with voxel-centroid filtering (thesis 5.1.2): every voxel keeps the running sum of
// its points, so its point is the centroid of all points that fell into it, and it is an obstacle
// if any of them was. Sums are kept relative to the voxel corner so float stays exact enough far
// from the origin, and weights may be negative so a composed map can take a submap back out.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "mapping/voxel_hash_map.h"

namespace cairn {

struct CloudPoint {
  Eigen::Vector3f p = Eigen::Vector3f::Zero();
  uint8_t r = 0, g = 0, b = 0;
  uint8_t obstacle = 0;
};

class VoxelCloud {
 public:
  explicit VoxelCloud(double resolution = 0.05, size_t expected_voxels = 1024);

  double resolution() const { return res_; }
  // Bytes held (table and scratch), for memory reports.
  size_t memory_bytes() const;
  // Voxels holding points (weight > 0).
  size_t size() const;
  void Clear() { voxels_.Clear(); }

  // Adds `weight` copies of a point (negative weights remove what an earlier call added).
  // Returns false for points outside the key range.
  bool Add(const Eigen::Vector3f& p, uint8_t r, uint8_t g, uint8_t b, bool obstacle, int32_t weight = 1);
  bool Add(const CloudPoint& c, int32_t weight = 1) { return Add(c.p, c.r, c.g, c.b, c.obstacle != 0, weight); }
  // Gray points of one image, summed per voxel in a small cache before one hash lookup per voxel
  // and image (mostly). Returns points dropped.
  //
  // With `cells`, also where the points are, for an occupancy map at twice this resolution
  // (OccupancyIntegrator::IntegrateCells): the key of each voxel that received a point strictly
  // inside it, i.e. with p * inv_res between two integers on every axis (once per stay in the
  // cache, so a key may repeat), and the indices of the other points, whose p * inv_res is an
  // integer on some axis (rare; float rounding may have moved them there).
  struct Cells {
    std::vector<uint64_t> interior;
    std::vector<uint32_t> on_face;
  };
  size_t AddBatch(const std::vector<Eigen::Vector3f>& p, const std::vector<uint8_t>& gray,
                  const std::vector<uint8_t>& obstacle, Cells* cells = nullptr);
  float inv_resolution() const { return inv_res_; }

  // Add() of many points at once; scattered points (a moved submap's cloud) are looked up with
  // prefetching, which hides most of the cache misses of a large table.
  void AddAll(const std::vector<CloudPoint>& points, int32_t weight);

  // Centroids, in key order of the hash table (not sorted).
  std::vector<CloudPoint> Points() const;
  // Centroids of this cloud and `other` together (same resolution), without changing either.
  std::vector<CloudPoint> MergedPoints(const VoxelCloud& other) const;
  template <class F>
  void ForEachPoint(F&& f) const {
    voxels_.ForEach([&](uint64_t key, const Accum& a) {
      if (a.n > 0) f(Centroid(key, a));
    });
  }

 private:
  struct Accum {
    float sx = 0, sy = 0, sz = 0;  // offsets from the voxel corner
    int32_t n = 0;
    int32_t sr = 0, sg = 0, sb = 0;
    int32_t obstacles = 0;
    void Merge(const Accum& o) {
      sx += o.sx; sy += o.sy; sz += o.sz;
      n += o.n; sr += o.sr; sg += o.sg; sb += o.sb;
      obstacles += o.obstacles;
    }
  };
  CloudPoint Centroid(uint64_t key, const Accum& a) const;
  void AddKeyed(uint64_t key, const CloudPoint& c, int32_t weight);

  // Sums of one image's points per voxel before they reach the table, direct mapped by key: stereo
  // noise moves neighbouring pixels between depth layers, so runs of one voxel along a row are
  // short, but the few voxels a stretch of rows hits stay here, and the table (megabytes, out of
  // the CPU caches) sees each about once per image.
  struct Pending {
    uint64_t key = VoxelKey::kEmpty;
    Eigen::Vector3f corner = Eigen::Vector3f::Zero();
    Accum sum;
    bool interior = false;  // a point strictly inside (for Cells)
  };
  static constexpr int kPendingBits = 12;

  double res_;
  float inv_res_;
  VoxelHashMap<Accum> voxels_;
  std::vector<uint64_t> keys_;  // scratch of AddAll
  std::vector<Pending> pending_;  // 1 << kPendingBits entries, used within AddBatch
};

}  // namespace cairn
