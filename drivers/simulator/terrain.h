#pragma once
// Procedural planetary-analogue terrain: a height grid (multi-octave noise, craters, boulders,
// one large crater with a steep rim) made of two planar triangles per cell, an albedo texture with
// detail at several scales, and a max-mipmap over the cell heights so that a ray finds its first
// hit by skipping whole quadtree nodes it passes above.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "drivers/simulator/world_options.h"

namespace cairn::sim {

struct TerrainHit {
  double t = -1.0;                                   // distance along the ray; < 0: no hit
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit surface normal
};

class Terrain {
 public:
  static Terrain Generate(const WorldOptions& options);

  double half_size() const { return half_size_; }
  double resolution() const { return res_; }
  // Height of the triangulated surface; clamped to the world's edge outside it.
  double Height(double x, double y) const;
  Eigen::Vector3d Normal(double x, double y) const;
  // Albedo in [0, 1]: the stored texture plus a fine procedural layer for near-range detail.
  float Albedo(double x, double y) const;
  // First hit of the ray origin + t * dir (dir unit length) with t in (0, t_max].
  TerrainHit Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max) const;
  size_t memory_bytes() const;
  double max_height() const { return flat_mip_.back(); }

 private:
  float H(int ix, int iy) const { return h_[static_cast<size_t>(iy) * static_cast<size_t>(n_) + static_cast<size_t>(ix)]; }
  void BuildMaxMipmap();
  void BuildAlbedo(const WorldOptions& options, const std::vector<Eigen::Vector4d>& rocks);

  double half_size_ = 0.0;
  double res_ = 0.1;
  int n_ = 0;       // vertices per side; cells per side is n_ - 1
  uint64_t seed_ = 0;
  std::vector<float> h_;
  std::vector<std::vector<float>> mip_;  // while building: level 0 per-cell maxima .. 1 x 1
  std::vector<int> mip_width_;
  std::vector<float> flat_mip_;        // all levels, level k at mip_offset_[k]
  std::vector<size_t> mip_offset_;
  std::vector<float> grain_;           // 256 x 256 tile of fine albedo detail in [-1, 1]
  static constexpr int kStartLevel = 4;
  int tex_n_ = 0;
  double tex_res_ = 0.0;
  std::vector<uint8_t> albedo_;
};

}  // namespace cairn::sim
