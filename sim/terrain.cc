#include "sim/terrain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <utility>

#include "sim/simd_clones.h"
#include "sim/terrain_generator.h"

namespace cairn::sim {

Terrain Terrain::Generate(const WorldOptions& options) {
  return Terrain(TerrainGenerator::Generate(options));
}

Terrain::Terrain(TerrainGrids grids)
    : half_size_(grids.half_size),
      res_(grids.resolution),
      inv_res_(1.0 / grids.resolution),
      n_(grids.n),
      h_(std::move(grids.heights)),
      grain_(std::move(grids.grain)),
      tex_n_(grids.texture_n),
      inv_tex_res_(1.0 / grids.texture_resolution),
      albedo_(std::move(grids.albedo)) {
  BuildMaxMipmap();
}

void Terrain::BuildMaxMipmap() {
  int w = n_ - 1;
  std::vector<float> level(static_cast<size_t>(w) * static_cast<size_t>(w));
  for (int y = 0; y < w; ++y) {
    for (int x = 0; x < w; ++x) {
      level[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)] =
          std::max({H(x, y), H(x + 1, y), H(x, y + 1), H(x + 1, y + 1)});
    }
  }
  // The steepest triangle bounds how fast the surface rises between any two points.
  double steepest = 0.0;
  for (int y = 0; y < w; ++y) {
    for (int x = 0; x < w; ++x) {
      const double h00 = H(x, y), h10 = H(x + 1, y), h01 = H(x, y + 1), h11 = H(x + 1, y + 1);
      steepest = std::max({steepest, std::hypot(h10 - h00, h11 - h10), std::hypot(h11 - h01, h01 - h00)});
    }
  }
  max_slope_ = steepest / res_ * (1.0 + 1e-6);
  mip_.clear();
  mip_width_.clear();
  mip_.push_back(std::move(level));
  mip_width_.push_back(w);
  while (w > 1) {
    const int nw = (w + 1) / 2;
    const std::vector<float>& prev = mip_.back();
    std::vector<float> next(static_cast<size_t>(nw) * static_cast<size_t>(nw), -std::numeric_limits<float>::max());
    for (int y = 0; y < w; ++y) {
      for (int x = 0; x < w; ++x) {
        float& m = next[static_cast<size_t>(y / 2) * static_cast<size_t>(nw) + static_cast<size_t>(x / 2)];
        m = std::max(m, prev[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)]);
      }
    }
    mip_.push_back(std::move(next));
    mip_width_.push_back(nw);
    w = nw;
  }
  flat_mip_.clear();
  mip_offset_.clear();
  for (const auto& m : mip_) {
    mip_offset_.push_back(flat_mip_.size());
    flat_mip_.insert(flat_mip_.end(), m.begin(), m.end());
  }
  mip_.clear();

  // The dilated pyramid: level 0 holds the maximum over a cell and its 8 neighbours, so a level-k
  // node bounds the terrain within one cell of its footprint; coarser levels are 2 x 2 maxima.
  dilated_mip_.assign(flat_mip_.size(), -std::numeric_limits<float>::max());
  const int w0 = mip_width_[0];
  for (int y = 0; y < w0; ++y) {
    for (int x = 0; x < w0; ++x) {
      float m = -std::numeric_limits<float>::max();
      for (int yy = std::max(0, y - 1); yy <= std::min(w0 - 1, y + 1); ++yy) {
        for (int xx = std::max(0, x - 1); xx <= std::min(w0 - 1, x + 1); ++xx) {
          m = std::max(m, flat_mip_[static_cast<size_t>(yy) * static_cast<size_t>(w0) + static_cast<size_t>(xx)]);
        }
      }
      dilated_mip_[static_cast<size_t>(y) * static_cast<size_t>(w0) + static_cast<size_t>(x)] = m;
    }
  }
  for (size_t k = 1; k < mip_width_.size(); ++k) {
    const int pw = mip_width_[k - 1], nw = mip_width_[k];
    const float* prev = dilated_mip_.data() + mip_offset_[k - 1];
    float* next = dilated_mip_.data() + mip_offset_[k];
    for (int y = 0; y < pw; ++y) {
      for (int x = 0; x < pw; ++x) {
        float& m = next[static_cast<size_t>(y / 2) * static_cast<size_t>(nw) + static_cast<size_t>(x / 2)];
        m = std::max(m, prev[static_cast<size_t>(y) * static_cast<size_t>(pw) + static_cast<size_t>(x)]);
      }
    }
  }
}

double Terrain::Height(double x, double y) const {
  const double gx = std::clamp((x + half_size_) / res_, 0.0, n_ - 1.000001);
  const double gy = std::clamp((y + half_size_) / res_, 0.0, n_ - 1.000001);
  const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
  const double u = gx - ix, v = gy - iy;
  const double h00 = H(ix, iy), h10 = H(ix + 1, iy), h01 = H(ix, iy + 1), h11 = H(ix + 1, iy + 1);
  // Cells split along the (0,0)-(1,1) diagonal, as in Raycast.
  return u >= v ? h00 + (h10 - h00) * u + (h11 - h10) * v : h00 + (h11 - h01) * u + (h01 - h00) * v;
}

Eigen::Vector3d Terrain::Normal(double x, double y) const {
  const double gx = std::clamp((x + half_size_) / res_, 0.0, n_ - 1.000001);
  const double gy = std::clamp((y + half_size_) / res_, 0.0, n_ - 1.000001);
  const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
  const double u = gx - ix, v = gy - iy;
  const double h00 = H(ix, iy), h10 = H(ix + 1, iy), h01 = H(ix, iy + 1), h11 = H(ix + 1, iy + 1);
  const double a = u >= v ? h10 - h00 : h11 - h01, b = u >= v ? h11 - h10 : h01 - h00;
  return Eigen::Vector3d(-a / res_, -b / res_, 1.0).normalized();
}

inline float Terrain::AlbedoAt(double x, double y) const {
  const double gx = std::clamp((x + half_size_) * inv_tex_res_, 0.0, tex_n_ - 1.000001);
  const double gy = std::clamp((y + half_size_) * inv_tex_res_, 0.0, tex_n_ - 1.000001);
  const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
  const float u = static_cast<float>(gx - ix), v = static_cast<float>(gy - iy);
  const size_t i = static_cast<size_t>(iy) * static_cast<size_t>(tex_n_) + static_cast<size_t>(ix);
  const size_t s = static_cast<size_t>(tex_n_);
  const float top = albedo_[i] + (albedo_[i + 1] - albedo_[i]) * u;
  const float bottom = albedo_[i + s] + (albedo_[i + s + 1] - albedo_[i + s]) * u;
  const float base = (top + (bottom - top) * v) * (1.0f / 255.0f);
  // Sub-texel grain (about 6 mm) so that close-range stereo still has texture: a seeded 256 x 256
  // tile of lattice values, bilinearly interpolated (a hash per lookup would cost as much as the
  // ray cast).
  const double qx = (x + half_size_) * 160.0, qy = (y + half_size_) * 160.0;
  const int gx0 = static_cast<int>(qx), gy0 = static_cast<int>(qy);
  const float fu = static_cast<float>(qx - gx0), fv = static_cast<float>(qy - gy0);
  const float* row0 = grain_.data() + (static_cast<size_t>(gy0 & 255) << 8);
  const float* row1 = grain_.data() + (static_cast<size_t>((gy0 + 1) & 255) << 8);
  const size_t c0 = static_cast<size_t>(gx0 & 255), c1 = static_cast<size_t>((gx0 + 1) & 255);
  const float g0 = row0[c0] + (row0[c1] - row0[c0]) * fu;
  const float g1 = row1[c0] + (row1[c1] - row1[c0]) * fu;
  const float grain = g0 + (g1 - g0) * fv;
  return std::clamp(base * (1.0f + 0.12f * grain), 0.0f, 1.0f);
}

float Terrain::Albedo(double x, double y) const { return AlbedoAt(x, y); }

// The same arithmetic as AlbedoAt, in three passes over a batch: texture coordinates
// (vectorized), the eight texel loads, and the two bilinear interpolations (vectorized).
CAIRN_SIM_CLONES void Terrain::Albedo(int count, const double* x, const double* y, float* albedo) const {
  constexpr int kBatch = 128;
  const double tex_max = tex_n_ - 1.000001;
  const int64_t stride = tex_n_;
  for (int b0 = 0; b0 < count; b0 += kBatch) {
    const int n = std::min(kBatch, count - b0);
    const double* __restrict xs = x + b0;
    const double* __restrict ys = y + b0;
    int64_t texel[kBatch];
    int grain0[kBatch], grain1[kBatch], col0[kBatch], col1[kBatch];
    float u[kBatch], v[kBatch], fu[kBatch], fv[kBatch];
    for (int i = 0; i < n; ++i) {
      const double gx = std::clamp((xs[i] + half_size_) * inv_tex_res_, 0.0, tex_max);
      const double gy = std::clamp((ys[i] + half_size_) * inv_tex_res_, 0.0, tex_max);
      const int ix = static_cast<int>(gx), iy = static_cast<int>(gy);
      u[i] = static_cast<float>(gx - ix);
      v[i] = static_cast<float>(gy - iy);
      texel[i] = iy * stride + ix;
      const double qx = (xs[i] + half_size_) * 160.0, qy = (ys[i] + half_size_) * 160.0;
      const int gx0 = static_cast<int>(qx), gy0 = static_cast<int>(qy);
      fu[i] = static_cast<float>(qx - gx0);
      fv[i] = static_cast<float>(qy - gy0);
      grain0[i] = (gy0 & 255) << 8;
      grain1[i] = ((gy0 + 1) & 255) << 8;
      col0[i] = gx0 & 255;
      col1[i] = (gx0 + 1) & 255;
    }
    float a00[kBatch], a10[kBatch], a01[kBatch], a11[kBatch], g00[kBatch], g10[kBatch], g01[kBatch], g11[kBatch];
    const uint8_t* tex = albedo_.data();
    const float* grain = grain_.data();
    for (int i = 0; i < n; ++i) {
      const uint8_t* t = tex + texel[i];
      a00[i] = t[0];
      a10[i] = t[1];
      a01[i] = t[stride];
      a11[i] = t[stride + 1];
      g00[i] = grain[grain0[i] + col0[i]];
      g10[i] = grain[grain0[i] + col1[i]];
      g01[i] = grain[grain1[i] + col0[i]];
      g11[i] = grain[grain1[i] + col1[i]];
    }
    float* __restrict out = albedo + b0;
    for (int i = 0; i < n; ++i) {
      const float top = a00[i] + (a10[i] - a00[i]) * u[i];
      const float bottom = a01[i] + (a11[i] - a01[i]) * u[i];
      const float base = (top + (bottom - top) * v[i]) * (1.0f / 255.0f);
      const float g0 = g00[i] + (g10[i] - g00[i]) * fu[i];
      const float g1 = g01[i] + (g11[i] - g01[i]) * fu[i];
      const float g = g0 + (g1 - g0) * fv[i];
      out[i] = std::clamp(base * (1.0f + 0.12f * g), 0.0f, 1.0f);
    }
  }
}

size_t Terrain::memory_bytes() const {
  size_t bytes = h_.size() * sizeof(float) + albedo_.size() + flat_mip_.size() * sizeof(float) +
                 dilated_mip_.size() * sizeof(float) + grain_.size() * sizeof(float);
  return bytes;
}

namespace {

using CellHit = Terrain::CellHit;

// The first hit of the ray (grid coordinates o + t d) with the two triangles of cell (ix, iy),
// split along its (0,0)-(1,1) diagonal, within [t_in, t_out] (the ray's stretch over the cell).
// Both triangles are intersected (two independent divisions) and the choice between them is made
// without branches: a triangle's hit counts inside its own half of the cell, and the earlier of
// two valid hits wins.
inline bool HitCell(const float* heights, size_t n, int ix, int iy, double ox, double oy, double oz, double dx,
                    double dy, double dz, double t_in, double t_out, CellHit* hit) {
  const float* p = heights + static_cast<size_t>(iy) * n + static_cast<size_t>(ix);
  const double h00 = p[0], h10 = p[1], h01 = p[n], h11 = p[n + 1];
  const double lx = ox - ix, ly = oy - iy;
  const double lo = t_in - 1e-9, hi = t_out + 1e-9;
  // Triangle 0 (u >= v) and triangle 1 (v >= u): height h00 + a u + b v over the cell. The ray's
  // height above a plane is num + den t; it meets the plane at -num / den (never within [lo, hi]
  // when den is 0: the quotient is then infinite or not a number).
  const double a0 = h10 - h00, b0 = h11 - h10, a1 = h11 - h01, b1 = h01 - h00;
  const double th0 = (oz - (h00 + a0 * lx + b0 * ly)) / -(dz - a0 * dx - b0 * dy);
  const double th1 = (oz - (h00 + a1 * lx + b1 * ly)) / -(dz - a1 * dx - b1 * dy);
  // Within [lo, hi] the ray is over the cell, so only the diagonal remains to be checked: u - v >= 0
  // on triangle 0, v - u >= 0 on triangle 1.
  constexpr double kTol = 1e-7;
  const double diag = lx - ly, ddiag = dx - dy;
  const bool ok0 = (th0 >= lo) & (th0 <= hi) & (th0 > 0.0) & (diag + th0 * ddiag >= -kTol);
  const bool ok1 = (th1 >= lo) & (th1 <= hi) & (th1 > 0.0) & (-(diag + th1 * ddiag) >= -kTol);
  if (!(ok0 | ok1)) return false;
  const bool pick1 = ok1 & (!ok0 | (th1 < th0));
  hit->t = pick1 ? th1 : th0;
  hit->a = pick1 ? a1 : a0;
  hit->b = pick1 ? b1 : b0;
  return true;
}

}  // namespace

TerrainHit Terrain::Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                            double t_max, double t_start) const {
  CellHit hit;
  if (!TraceNear(ToGrid(origin, dir), t_max, t_start, &hit)) return TerrainHit{};
  const double nx = -hit.a * inv_res_, ny = -hit.b * inv_res_;
  const double inv_norm = 1.0 / std::sqrt(nx * nx + ny * ny + 1.0);
  return TerrainHit{hit.t, Eigen::Vector3d(nx * inv_norm, ny * inv_norm, inv_norm)};
}

inline bool Terrain::TraceNear(const GridRay& r, double t_max, double t_start, CellHit* hit) const {
  const int cells = n_ - 1;
  // Copies, so that the ray itself stays in registers (only the rare fallback needs it in memory).
  const double ox = r.ox, oy = r.oy, oz = r.oz, dx = r.dx, dy = r.dy, dz = r.dz;
  const double top_height = flat_mip_.back();
  if (dz >= 0.0 && oz > top_height) return false;
  double t = t_start;
  const double sx = ox + t * dx, sy = oy + t * dy;
  if (t_start > 0.0 && sx >= 0.0 && sy >= 0.0 && sx < cells && sy < cells) {
    // A caller-supplied start lies close to the surface: walk single cells first (the finest
    // level of the traversal below, without its climbs and descents). The walk ends where the
    // ray leaves the grid, passes t_max, or rises out of the slab below the highest point.
    if (t >= t_max) return false;
    constexpr double inf = std::numeric_limits<double>::infinity();
    const double inv_dx = r.inv_dx, inv_dy = r.inv_dy;
    int ix = static_cast<int>(sx), iy = static_cast<int>(sy);
    const float* cell_max = flat_mip_.data();
    const size_t row = static_cast<size_t>(cells);
    const int step_x = dx > 0 ? 1 : -1, step_y = dy > 0 ? 1 : -1;
    const double edge_x = dx > 0 ? 1.0 : 0.0, edge_y = dy > 0 ? 1.0 : 0.0;
    double tx = dx != 0.0 ? (ix + edge_x - ox) * inv_dx : inf;
    double ty = dy != 0.0 ? (iy + edge_y - oy) * inv_dy : inf;
    double z0 = oz + t * dz;
    for (int step = 0; step < kNearCells; ++step) {
      const double t_exit = std::min(std::min(tx, ty), t_max);
      const double z1 = oz + t_exit * dz;
      if (std::min(z0, z1) <= cell_max[static_cast<size_t>(iy) * row + static_cast<size_t>(ix)] &&
          HitCell(h_.data(), static_cast<size_t>(n_), ix, iy, ox, oy, oz, dx, dy, dz, t, t_exit, hit)) {
        return true;
      }
      if (t_exit >= t_max || (dz >= 0.0 && z1 > top_height)) return false;
      t = t_exit;
      z0 = z1;
      if (tx <= ty) {
        ix += step_x;
        if (ix < 0 || ix >= cells) return false;
        tx = (ix + edge_x - ox) * inv_dx;
      } else {
        iy += step_y;
        if (iy < 0 || iy >= cells) return false;
        ty = (iy + edge_y - oy) * inv_dy;
      }
    }
  }
  const GridRay fallback{ox, oy, oz, dx, dy, dz, r.inv_dx, r.inv_dy};
  return TracePyramid(fallback, t_max, t, hit);
}

namespace {

constexpr int kRayBatch = 128;

// The start cell of each ray, where the start is inside the grid (straight-line code over arrays,
// vectorized); elsewhere the search interval is empty (lo = infinity).
CAIRN_SIM_CLONES void StartCells(int count, double ox, double oy, double oz, double top_height, int cells,
                                 int stride, const double* __restrict dxs, const double* __restrict dys,
                                 const double* __restrict dzs, const double* __restrict t_max,
                                 const double* __restrict t_start, int* __restrict cell, double* __restrict lo,
                                 double* __restrict hi, double* __restrict lx, double* __restrict ly) {
  constexpr double kInf = std::numeric_limits<double>::infinity();
  const bool above_all = oz > top_height;
  for (int i = 0; i < count; ++i) {
    const double t = t_start[i];
    const double sx = ox + t * dxs[i], sy = oy + t * dys[i];
    const bool ok = (t > 0.0) & (sx >= 0.0) & (sy >= 0.0) & (sx < cells) & (sy < cells) & (t < t_max[i]) &
                    !((dzs[i] >= 0.0) & above_all);
    const int ix = static_cast<int>(ok ? sx : 0.0), iy = static_cast<int>(ok ? sy : 0.0);
    cell[i] = iy * stride + ix;
    lx[i] = ox - ix;
    ly[i] = oy - iy;
    lo[i] = ok ? t - 1e-9 : kInf;
    hi[i] = t_max[i] + 1e-9;
  }
}

// HitCell's arithmetic for every ray's start cell, lane by lane (vectorized). The search runs from
// the start to t_max, the hit confined to the cell's square: the ray's stretch over the cell.
CAIRN_SIM_CLONES void HitStartCells(int count, double oz, const double* __restrict dxs,
                                    const double* __restrict dys, const double* __restrict dzs,
                                    const double* __restrict h00, const double* __restrict h10,
                                    const double* __restrict h01, const double* __restrict h11,
                                    const double* __restrict lo, const double* __restrict hi,
                                    const double* __restrict lx, const double* __restrict ly, double* __restrict hit,
                                    double* __restrict th_best, double* __restrict a_best,
                                    double* __restrict b_best) {
  constexpr double kTol = 1e-7;
  for (int i = 0; i < count; ++i) {
    const double dx = dxs[i], dy = dys[i], dz = dzs[i];
    const double a0 = h10[i] - h00[i], b0 = h11[i] - h10[i], a1 = h11[i] - h01[i], b1 = h01[i] - h00[i];
    const double th0 = (oz - (h00[i] + a0 * lx[i] + b0 * ly[i])) / -(dz - a0 * dx - b0 * dy);
    const double th1 = (oz - (h00[i] + a1 * lx[i] + b1 * ly[i])) / -(dz - a1 * dx - b1 * dy);
    const double u0 = lx[i] + th0 * dx, v0 = ly[i] + th0 * dy, u1 = lx[i] + th1 * dx, v1 = ly[i] + th1 * dy;
    const bool ok0 = (th0 >= lo[i]) & (th0 <= hi[i]) & (th0 > 0.0) & (u0 >= -kTol) & (u0 <= 1 + kTol) &
                     (v0 >= -kTol) & (v0 <= 1 + kTol) & (u0 - v0 >= -kTol);
    const bool ok1 = (th1 >= lo[i]) & (th1 <= hi[i]) & (th1 > 0.0) & (u1 >= -kTol) & (u1 <= 1 + kTol) &
                     (v1 >= -kTol) & (v1 <= 1 + kTol) & (v1 - u1 >= -kTol);
    const bool pick1 = ok1 & (!ok0 | (th1 < th0));
    hit[i] = (ok0 | ok1) ? 1.0 : 0.0;
    th_best[i] = pick1 ? th1 : th0;
    a_best[i] = pick1 ? a1 : a0;
    b_best[i] = pick1 ? b1 : b0;
  }
}

}  // namespace

// Most rays of a batch, started close to the surface, meet it in the cell where they start. That
// cell is searched for all of them at once, in passes that vectorize around one that loads the
// heights (the same arithmetic as HitCell, lane by lane); the rays that miss it walk on one at a
// time.
CAIRN_SIM_CLONES void Terrain::TraceRays(const RayBatch& rays, CellHit* hits, bool* found) const {
  const size_t n = static_cast<size_t>(n_);
  const double oz = rays.oz;
  for (int b0 = 0; b0 < rays.count; b0 += kRayBatch) {
    const int count = std::min(kRayBatch, rays.count - b0);
    int cell[kRayBatch];
    double lo[kRayBatch], hi[kRayBatch], lx[kRayBatch], ly[kRayBatch];
    StartCells(count, rays.ox, rays.oy, oz, flat_mip_.back(), n_ - 1, n_, rays.dx + b0, rays.dy + b0, rays.dz + b0,
               rays.t_max + b0, rays.t_start + b0, cell, lo, hi, lx, ly);
    double h00[kRayBatch], h10[kRayBatch], h01[kRayBatch], h11[kRayBatch];
    const float* heights = h_.data();
    for (int i = 0; i < count; ++i) {
      const float* p = heights + cell[i];
      h00[i] = p[0];
      h10[i] = p[1];
      h01[i] = p[n];
      h11[i] = p[n + 1];
    }
    double hit[kRayBatch], th[kRayBatch], a[kRayBatch], b[kRayBatch];
    HitStartCells(count, oz, rays.dx + b0, rays.dy + b0, rays.dz + b0, h00, h10, h01, h11, lo, hi, lx, ly, hit, th,
                  a, b);
    for (int i = 0; i < count; ++i) {
      const size_t j = static_cast<size_t>(b0 + i);
      if (hit[i] != 0.0) {
        hits[j] = CellHit{th[i], a[i], b[i]};
        found[j] = true;
      } else {
        constexpr double kInf = std::numeric_limits<double>::infinity();
        const double dx = rays.dx[j], dy = rays.dy[j];
        const GridRay r{rays.ox, rays.oy, oz, dx, dy, rays.dz[j], dx != 0.0 ? 1.0 / dx : kInf,
                        dy != 0.0 ? 1.0 / dy : kInf};
        found[j] = TraceNear(r, rays.t_max[j], rays.t_start[j], &hits[j]);
      }
    }
  }
}

// The pyramid traversal from t_from (0: from the camera); the clip to the grid and the slab comes
// first.
bool Terrain::TracePyramid(const GridRay& r, double t_max, double t_from, CellHit* hit) const {
  const int cells = n_ - 1;
  const size_t n = static_cast<size_t>(n_);
  const double ox = r.ox, oy = r.oy, oz = r.oz, dx = r.dx, dy = r.dy, dz = r.dz;
  const double top_height = flat_mip_.back();
  if (dz >= 0.0 && oz > top_height) return false;
  const double inf = std::numeric_limits<double>::infinity();
  const double inv_dx = r.inv_dx, inv_dy = r.inv_dy;
  double t0 = std::max(1e-6, t_from), t1 = t_max;
  // Clip to the grid's footprint and to the slab below the highest point.
  if (dx != 0.0) {
    const double ta = -ox * inv_dx, tb = (cells - ox) * inv_dx;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  } else if (ox < 0.0 || ox > cells) {
    return false;
  }
  if (dy != 0.0) {
    const double ta = -oy * inv_dy, tb = (cells - oy) * inv_dy;
    t0 = std::max(t0, std::min(ta, tb));
    t1 = std::min(t1, std::max(ta, tb));
  } else if (oy < 0.0 || oy > cells) {
    return false;
  }
  if (oz > top_height) t0 = std::max(t0, (top_height - oz) / dz);  // dz < 0 here
  if (dz > 0.0) t1 = std::min(t1, (top_height - oz) / dz);
  if (t0 >= t1) return false;
  double t = t0;
  // Grid coordinates are non-negative here, so truncation is floor (and avoids a libm call).
  int ix = std::clamp(static_cast<int>(ox + t * dx), 0, cells - 1);
  int iy = std::clamp(static_cast<int>(oy + t * dy), 0, cells - 1);
  const int top = static_cast<int>(mip_width_.size()) - 1;
  // Starting below the root saves descents; rays rarely clear nodes larger than this.
  int level = std::min(top, kStartLevel);
  for (int guard = 0; guard < 1 << 20; ++guard) {
    const int cx = ix >> level, cy = iy >> level, s = 1 << level;
    const double tx = dx > 0 ? ((cx + 1) * s - ox) * inv_dx : dx < 0 ? (cx * s - ox) * inv_dx : inf;
    const double ty = dy > 0 ? ((cy + 1) * s - oy) * inv_dy : dy < 0 ? (cy * s - oy) * inv_dy : inf;
    const double t_exit = std::min({tx, ty, t1});
    const float hmax = flat_mip_[mip_offset_[static_cast<size_t>(level)] + static_cast<size_t>(cy) * static_cast<size_t>(mip_width_[static_cast<size_t>(level)]) + static_cast<size_t>(cx)];
    const double z0 = oz + t * dz, z1 = oz + t_exit * dz;
    bool below = std::min(z0, z1) <= hmax;
    if (below && level > 0) {
      // Skip to where the ray drops to the node's maximum, then look at the children.
      if (z0 > hmax) {
        t = (hmax - oz) / dz;
        ix = std::clamp(static_cast<int>(ox + t * dx), cx * s, std::min(cells, (cx + 1) * s) - 1);
        iy = std::clamp(static_cast<int>(oy + t * dy), cy * s, std::min(cells, (cy + 1) * s) - 1);
      }
      --level;
      continue;
    }
    if (below && HitCell(h_.data(), n, ix, iy, ox, oy, oz, dx, dy, dz, t, t_exit, hit)) return true;
    if (t_exit >= t1) return false;
    // Step into the neighbouring node and allow the traversal to climb one level.
    t = t_exit;
    if (tx <= ty) {
      ix = dx > 0 ? (cx + 1) * s : cx * s - 1;
      iy = std::clamp(static_cast<int>(oy + t * dy), cy * s, (cy + 1) * s - 1);
    } else {
      iy = dy > 0 ? (cy + 1) * s : cy * s - 1;
      ix = std::clamp(static_cast<int>(ox + t * dx), cx * s, (cx + 1) * s - 1);
    }
    if (ix < 0 || iy < 0 || ix >= cells || iy >= cells) {
      if (tx <= ty) return false;  // left the grid through an x edge
      if (iy < 0 || iy >= cells) return false;
    }
    ix = std::clamp(ix, 0, cells - 1);
    iy = std::clamp(iy, 0, cells - 1);
    // Climb only into a new parent: re-testing the parent just left would descend again at once.
    if (level < kStartLevel && level < top && ((ix >> (level + 1)) != (cx >> 1) || (iy >> (level + 1)) != (cy >> 1))) {
      ++level;
    }
  }
  return false;
}

double Terrain::ClearDistance(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir, double spread,
                              double t_max) const {
  const int cells = n_ - 1;
  const double inf = std::numeric_limits<double>::infinity();
  const double ox = (origin.x() + half_size_) * inv_res_, oy = (origin.y() + half_size_) * inv_res_, oz = origin.z();
  const double dx = dir.x() * inv_res_, dy = dir.y() * inv_res_;
  // At distance t every ray of the bundle lies within t * spread of the central ray's point, so
  // the bundle's lowest point is oz + t * dzl, and its horizontal reach stays within one cell of
  // the central point while t * spread <= res_: the dilated pyramid bounds the terrain there.
  const double slack = spread * (1.0 + 1e-9) + 1e-12;
  const double dzl = dir.z() - slack;
  const double top_height = flat_mip_.back();
  double t0 = 0.0;
  if (oz > top_height) {
    if (dzl >= 0.0) return t_max;  // the whole bundle stays above the highest point
    t0 = std::min(t_max, (top_height - oz) / dzl);
  }
  if (ox < 0.0 || oy < 0.0 || ox > cells || oy > cells) return t0;
  double t1 = std::min(t_max, res_ / slack);
  if (dx != 0.0) t1 = std::min(t1, ((dx > 0 ? cells : 0) - ox) / dx);
  if (dy != 0.0) t1 = std::min(t1, ((dy > 0 ? cells : 0) - oy) / dy);
  if (t0 >= t1) return t0;

  const int top = static_cast<int>(mip_width_.size()) - 1;
  double t = t0;
  int ix = std::clamp(static_cast<int>(ox + t * dx), 0, cells - 1);
  int iy = std::clamp(static_cast<int>(oy + t * dy), 0, cells - 1);
  int level = std::min(top, kStartLevel);
  const double inv_dx = dx != 0.0 ? 1.0 / dx : inf, inv_dy = dy != 0.0 ? 1.0 / dy : inf;
  for (int guard = 0; guard < 1 << 20; ++guard) {
    const int cx = ix >> level, cy = iy >> level, s = 1 << level;
    const double tx = dx > 0 ? ((cx + 1) * s - ox) * inv_dx : dx < 0 ? (cx * s - ox) * inv_dx : inf;
    const double ty = dy > 0 ? ((cy + 1) * s - oy) * inv_dy : dy < 0 ? (cy * s - oy) * inv_dy : inf;
    const double t_exit = std::min({tx, ty, t1});
    const size_t node = mip_offset_[static_cast<size_t>(level)] +
                        static_cast<size_t>(cy) * static_cast<size_t>(mip_width_[static_cast<size_t>(level)]) +
                        static_cast<size_t>(cx);
    const float hmax = dilated_mip_[node];
    const double z0 = oz + t * dzl, z1 = oz + t_exit * dzl;
    if (std::min(z0, z1) <= hmax) {
      if (z0 > hmax) {
        // Clear until the bundle's lowest point drops to the node's maximum.
        t = std::min(t_exit, (hmax - oz) / dzl);
        if (level == 0) return t;
        ix = std::clamp(static_cast<int>(ox + t * dx), cx * s, std::min(cells, (cx + 1) * s) - 1);
        iy = std::clamp(static_cast<int>(oy + t * dy), cy * s, std::min(cells, (cy + 1) * s) - 1);
      } else if (level == 0) {
        return t;
      }
      --level;
      continue;
    }
    if (t_exit >= t1) return t1;
    t = t_exit;
    if (tx <= ty) {
      ix = dx > 0 ? (cx + 1) * s : cx * s - 1;
      iy = std::clamp(static_cast<int>(oy + t * dy), cy * s, (cy + 1) * s - 1);
    } else {
      iy = dy > 0 ? (cy + 1) * s : cy * s - 1;
      ix = std::clamp(static_cast<int>(ox + t * dx), cx * s, (cx + 1) * s - 1);
    }
    if (ix < 0 || iy < 0 || ix >= cells || iy >= cells) return t;
    if (level < kStartLevel && level < top && ((ix >> (level + 1)) != (cx >> 1) || (iy >> (level + 1)) != (cy >> 1))) {
      ++level;
    }
  }
  return t;
}

}  // namespace cairn::sim
