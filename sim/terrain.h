#pragma once
// The planetary-analogue terrain as renderers and scorers query it: a height grid made of two planar
// triangles per cell and an albedo texture (TerrainGenerator builds both), heights, normals and
// albedo at points, and ray casting. A max-mipmap over the cell heights lets a ray find its first
// hit by skipping whole quadtree nodes it passes above. A renderer starts each ray's search where
// the ray is known to be clear: a dilated copy of the max-mipmap bounds bundles of neighbouring
// rays (ClearDistance), and the steepest slope relates rays of neighbouring pixels (max_slope).

#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

#include <Eigen/Core>

#include "sim/world_options.h"

namespace cairn::sim {

// What a terrain is made of, as TerrainGenerator builds it, on the square |x|, |y| <= half_size:
// heights at n x n vertices `resolution` apart and albedo (0 .. 255) at texture_n x texture_n texels
// `texture_resolution` apart, both row-major from the corner (-half_size, -half_size), and a
// 256 x 256 tile of fine albedo detail in [-1, 1].
struct TerrainGrids {
  double half_size = 0.0;
  double resolution = 0.1;
  int n = 0;
  std::vector<float> heights;
  double texture_resolution = 0.0;
  int texture_n = 0;
  std::vector<uint8_t> albedo;
  std::vector<float> grain;
};

struct TerrainHit {
  double t = -1.0;                                   // distance along the ray; < 0: no hit
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  // unit surface normal
};

class Terrain {
 public:
  // The terrain of a world (TerrainGenerator).
  static Terrain Generate(const WorldOptions& options);
  // Takes the grids over and builds the max-mipmaps the ray casts search.
  explicit Terrain(TerrainGrids grids);

  double half_size() const { return half_size_; }
  double resolution() const { return res_; }
  // Height of the triangulated surface; clamped to the world's edge outside it.
  double Height(double x, double y) const;
  Eigen::Vector3d Normal(double x, double y) const;
  // Albedo in [0, 1]: the stored texture plus a fine procedural layer for near-range detail.
  float Albedo(double x, double y) const;
  // The same for many points at once.
  void Albedo(int count, const double* x, const double* y, float* albedo) const;
  // First hit of the ray origin + t * dir (dir unit length) with t in (0, t_max]. `t_start` is a
  // distance the caller knows the ray to be clear up to (ClearDistance); the search starts there.
  TerrainHit Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double t_max,
                     double t_start = 0.0) const;
  // A distance up to which every ray origin + t * d with |d - dir| <= spread (d, dir unit length)
  // is certainly clear of the terrain (t_max when it is clear all the way): a bound shared by a
  // bundle of neighbouring pixel rays, found by one traversal of a dilated max-mipmap.
  double ClearDistance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double spread,
                       double t_max) const;

  // Raycast for many rays from one origin, for renderers that prepare rays a row at a time (the
  // preparation has the divisions and vectorizes). In grid coordinates: x, y in cells from the
  // grid's corner, z in metres (origin: (x + half_size()) / resolution(), ...; directions: the
  // unit world direction's x and y over resolution(), its z); t stays the distance along the unit
  // world ray. Ray i is searched over [t_start[i], t_max[i]]; found[i] tells whether hits[i] holds
  // its hit: the distance and the hit triangle's height steps per cell along x and y (its normal
  // is (-a, -b, resolution()), normalized).
  struct RayBatch {
    double ox, oy, oz;
    int count;
    const double *dx, *dy, *dz, *t_max, *t_start;
  };
  struct CellHit {
    double t = 0.0, a = 0.0, b = 0.0;
  };
  void TraceRays(const RayBatch& rays, CellHit* hits, bool* found) const;

  size_t memory_bytes() const;
  double max_height() const { return flat_mip_.back(); }
  // An upper bound of the surface's slope: |Height(p) - Height(q)| <= max_slope() |p - q|.
  double max_slope() const { return max_slope_; }

 private:
  float H(int ix, int iy) const { return h_[static_cast<size_t>(iy) * static_cast<size_t>(n_) + static_cast<size_t>(ix)]; }
  void BuildMaxMipmap();
  float AlbedoAt(double x, double y) const;
  // A ray in grid coordinates (see RayBatch), with the inverses of its horizontal components.
  struct GridRay {
    double ox, oy, oz, dx, dy, dz, inv_dx, inv_dy;
  };
  GridRay ToGrid(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir) const {
    const double dx = dir.x() * inv_res_, dy = dir.y() * inv_res_;
    constexpr double kInf = std::numeric_limits<double>::infinity();
    return GridRay{(origin.x() + half_size_) * inv_res_, (origin.y() + half_size_) * inv_res_, origin.z(), dx, dy,
                   dir.z(), dx != 0.0 ? 1.0 / dx : kInf, dy != 0.0 ? 1.0 / dy : kInf};
  }
  // From t_start, single cells first (a start close to the surface), then TracePyramid.
  bool TraceNear(const GridRay& ray, double t_max, double t_start, CellHit* hit) const;
  bool TracePyramid(const GridRay& ray, double t_max, double t_from, CellHit* hit) const;

  double half_size_ = 0.0;
  double res_ = 0.1;
  double inv_res_ = 10.0;
  double max_slope_ = 0.0;
  int n_ = 0;       // vertices per side; cells per side is n_ - 1
  std::vector<float> h_;
  std::vector<std::vector<float>> mip_;  // while building: level 0 per-cell maxima .. 1 x 1
  std::vector<int> mip_width_;
  std::vector<float> flat_mip_;        // all levels, level k at mip_offset_[k]
  std::vector<float> dilated_mip_;     // same layout; level 0 is the maximum over 3 x 3 cells
  std::vector<size_t> mip_offset_;
  std::vector<float> grain_;           // 256 x 256 tile of fine albedo detail in [-1, 1]
  static constexpr int kStartLevel = 4;
  static constexpr int kNearCells = 24;  // single-cell steps before a started ray uses the pyramid
  int tex_n_ = 0;
  double inv_tex_res_ = 0.0;
  std::vector<uint8_t> albedo_;
};

}  // namespace cairn::sim
