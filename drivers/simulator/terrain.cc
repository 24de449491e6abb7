#include "drivers/simulator/terrain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "drivers/simulator/sim_random.h"

namespace cairn::sim {
namespace {

// Lattice value in [-1, 1] for integer coordinates of one noise layer.
inline double LatticeValue(uint64_t seed, int64_t ix, int64_t iy, uint64_t layer) {
  const uint64_t h = SimRandom::Mix(seed ^ SimRandom::Mix(static_cast<uint64_t>(ix) * 0x9E3779B97F4A7C15ull ^
                                                          static_cast<uint64_t>(iy) * 0xC2B2AE3D27D4EB4Full ^
                                                          layer * 0x165667B19E3779F9ull));
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

// Value noise with quintic fade (C2), wavelength 1 in lattice units.
double ValueNoise(uint64_t seed, double x, double y, uint64_t layer) {
  const double fx = std::floor(x), fy = std::floor(y);
  const int64_t ix = static_cast<int64_t>(fx), iy = static_cast<int64_t>(fy);
  const double u = x - fx, v = y - fy;
  const double su = u * u * u * (u * (u * 6 - 15) + 10), sv = v * v * v * (v * (v * 6 - 15) + 10);
  const double a = LatticeValue(seed, ix, iy, layer), b = LatticeValue(seed, ix + 1, iy, layer);
  const double c = LatticeValue(seed, ix, iy + 1, layer), d = LatticeValue(seed, ix + 1, iy + 1, layer);
  return (a + (b - a) * su) * (1 - sv) + (c + (d - c) * su) * sv;
}

// Fractal sum of value noise from `wavelength` down by halves, amplitudes falling with `gain`.
double Fbm(uint64_t seed, double x, double y, double wavelength, int octaves, double gain,
           uint64_t layer) {
  double sum = 0.0, amp = 1.0, norm = 0.0;
  for (int k = 0; k < octaves; ++k) {
    sum += amp * ValueNoise(seed, x / wavelength, y / wavelength, layer * 64 + static_cast<uint64_t>(k));
    norm += amp;
    amp *= gain;
    wavelength *= 0.5;
  }
  return sum / norm;
}

// Adds `profile(distance / radius)` to every vertex within `reach * radius` of (cx, cy).
template <class Profile>
void Stamp(std::vector<float>& h, int n, double half, double res, double cx, double cy,
           double radius, double reach, Profile profile) {
  const double r = radius * reach;
  const int x0 = std::max(0, static_cast<int>(std::floor((cx - r + half) / res)));
  const int x1 = std::min(n - 1, static_cast<int>(std::ceil((cx + r + half) / res)));
  const int y0 = std::max(0, static_cast<int>(std::floor((cy - r + half) / res)));
  const int y1 = std::min(n - 1, static_cast<int>(std::ceil((cy + r + half) / res)));
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const double dx = ix * res - half - cx, dy = iy * res - half - cy;
      const double s = std::sqrt(dx * dx + dy * dy) / radius;
      if (s < reach) h[static_cast<size_t>(iy) * static_cast<size_t>(n) + static_cast<size_t>(ix)] += static_cast<float>(profile(s));
    }
  }
}

}  // namespace

Terrain Terrain::Generate(const WorldOptions& o) {
  Terrain t;
  t.half_size_ = o.size / 2;
  t.res_ = o.resolution;
  t.n_ = static_cast<int>(std::lround(o.size / o.resolution)) + 1;
  t.seed_ = static_cast<uint64_t>(o.seed);
  const int n = t.n_;
  const double half = t.half_size_, res = t.res_;
  t.h_.assign(static_cast<size_t>(n) * static_cast<size_t>(n), 0.0f);

  // Rolling ground: wavelengths from 24 m down to ~0.4 m.
  for (int iy = 0; iy < n; ++iy) {
    for (int ix = 0; ix < n; ++ix) {
      const double x = ix * res - half, y = iy * res - half;
      t.h_[static_cast<size_t>(iy) * static_cast<size_t>(n) + static_cast<size_t>(ix)] =
          static_cast<float>(o.relief * Fbm(t.seed_, x, y, 24.0, 7, 0.45, 1));
    }
  }
  SimRandom rng = SimRandom::Stream(t.seed_, 17);
  const double hectares = o.size * o.size / 1e4;
  // Small craters: bowl with a raised rim, more small ones than large ones.
  const int craters = static_cast<int>(std::lround(o.crater_density * hectares));
  for (int i = 0; i < craters; ++i) {
    const double cx = rng.Uniform(-half, half), cy = rng.Uniform(-half, half);
    const double r = 0.5 * std::pow(8.0, rng.Uniform() * rng.Uniform());
    const double depth = 0.18 * r, rim = 0.05 * r;
    Stamp(t.h_, n, half, res, cx, cy, r, 2.0, [&](double s) {
      return s < 1.0 ? depth * (s * s - 1.0) + rim * s * s * s * s : rim * std::exp(-(s - 1.0) * (s - 1.0) / 0.08);
    });
  }
  // One large crater with steep inner walls: a cliff-like negative edge for the classifier.
  if (o.big_crater) {
    const double r = std::min(10.0, o.size / 6);
    const double cx = rng.Uniform(-half / 2, half / 2), cy = rng.Uniform(-half / 2, half / 2);
    const double depth = 0.3 * r, rim = 0.08 * r;
    Stamp(t.h_, n, half, res, cx, cy, r, 1.8, [&](double s) {
      const double s8 = std::pow(s, 8.0);
      return s < 1.0 ? depth * (s8 - 1.0) + rim * s8 : rim * std::exp(-(s - 1.0) * (s - 1.0) / 0.05);
    });
  }
  // Boulders: hemispheroids standing on the ground (positive steps).
  std::vector<Eigen::Vector4d> rocks;
  const int rock_count = static_cast<int>(std::lround(o.rock_density * hectares));
  for (int i = 0; i < rock_count; ++i) {
    const double cx = rng.Uniform(-half, half), cy = rng.Uniform(-half, half);
    const double r = 0.05 * std::pow(10.0, rng.Uniform() * rng.Uniform());
    const double hr = r * rng.Uniform(0.5, 0.9);
    rocks.emplace_back(cx, cy, r, hr);
    Stamp(t.h_, n, half, res, cx, cy, r, 1.0, [&](double s) { return hr * std::sqrt(std::max(0.0, 1.0 - s * s)); });
  }
  t.BuildMaxMipmap();
  t.BuildAlbedo(o, rocks);
  return t;
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
}

void Terrain::BuildAlbedo(const WorldOptions& o, const std::vector<Eigen::Vector4d>& rocks) {
  tex_res_ = res_ / 4;
  tex_n_ = static_cast<int>(std::lround(2 * half_size_ / tex_res_)) + 1;
  std::vector<float> a(static_cast<size_t>(tex_n_) * static_cast<size_t>(tex_n_));
  for (int iy = 0; iy < tex_n_; ++iy) {
    for (int ix = 0; ix < tex_n_; ++ix) {
      const double x = ix * tex_res_ - half_size_, y = iy * tex_res_ - half_size_;
      // Large patches (regolith colour) and fine grains, with most energy at stereo-relevant scales.
      const double coarse = Fbm(seed_, x, y, 8.0, 4, 0.6, 2);
      const double fine = Fbm(seed_, x, y, 0.4, 4, 0.7, 3);
      a[static_cast<size_t>(iy) * static_cast<size_t>(tex_n_) + static_cast<size_t>(ix)] =
          static_cast<float>(0.5 + o.albedo_contrast * (0.5 * coarse + 0.9 * fine));
    }
  }
  // Rocks are darker than the regolith around them.
  for (const Eigen::Vector4d& r : rocks) {
    const int x0 = std::max(0, static_cast<int>((r[0] - r[2] + half_size_) / tex_res_));
    const int x1 = std::min(tex_n_ - 1, static_cast<int>((r[0] + r[2] + half_size_) / tex_res_) + 1);
    const int y0 = std::max(0, static_cast<int>((r[1] - r[2] + half_size_) / tex_res_));
    const int y1 = std::min(tex_n_ - 1, static_cast<int>((r[1] + r[2] + half_size_) / tex_res_) + 1);
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) {
        const double dx = ix * tex_res_ - half_size_ - r[0], dy = iy * tex_res_ - half_size_ - r[1];
        if (dx * dx + dy * dy < r[2] * r[2]) a[static_cast<size_t>(iy) * static_cast<size_t>(tex_n_) + static_cast<size_t>(ix)] *= 0.75f;
      }
    }
  }
  grain_.resize(256 * 256);
  for (size_t i = 0; i < grain_.size(); ++i) {
    grain_[i] = static_cast<float>(LatticeValue(seed_, static_cast<int64_t>(i & 255), static_cast<int64_t>(i >> 8), 9));
  }
  albedo_.resize(a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    albedo_[i] = static_cast<uint8_t>(std::clamp(std::lround(a[i] * 255.0f), 0l, 255l));
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

float Terrain::Albedo(double x, double y) const {
  const double gx = std::clamp((x + half_size_) / tex_res_, 0.0, tex_n_ - 1.000001);
  const double gy = std::clamp((y + half_size_) / tex_res_, 0.0, tex_n_ - 1.000001);
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
  auto g = [&](int a, int b) { return grain_[static_cast<size_t>(((b & 255) << 8) | (a & 255))]; };
  const float g0 = g(gx0, gy0) + (g(gx0 + 1, gy0) - g(gx0, gy0)) * fu;
  const float g1 = g(gx0, gy0 + 1) + (g(gx0 + 1, gy0 + 1) - g(gx0, gy0 + 1)) * fu;
  const float grain = g0 + (g1 - g0) * fv;
  return std::clamp(base * (1.0f + 0.12f * grain), 0.0f, 1.0f);
}

size_t Terrain::memory_bytes() const {
  size_t bytes = h_.size() * sizeof(float) + albedo_.size() + flat_mip_.size() * sizeof(float);
  return bytes;
}

TerrainHit Terrain::Raycast(const Eigen::Vector3d& origin, const Eigen::Vector3d& dir,
                            double t_max) const {
  TerrainHit miss;
  const int cells = n_ - 1;
  // Grid coordinates: x, y in cells, z in metres; t stays the distance along the unit ray.
  const double ox = (origin.x() + half_size_) / res_, oy = (origin.y() + half_size_) / res_, oz = origin.z();
  const double dx = dir.x() / res_, dy = dir.y() / res_, dz = dir.z();
  const int top = static_cast<int>(mip_width_.size()) - 1;
  const double top_height = flat_mip_.back();
  if (dz >= 0.0 && oz > top_height) return miss;
  double t0 = 1e-6, t1 = t_max;
  // Clip to the grid's footprint and to the slab below the highest point.
  const double inf = std::numeric_limits<double>::infinity();
  for (const auto& [o, d] : {std::pair{ox, dx}, std::pair{oy, dy}}) {
    if (d == 0.0) {
      if (o < 0.0 || o > cells) return miss;
      continue;
    }
    double ta = (0.0 - o) / d, tb = (cells - o) / d;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  if (dz < 0.0) t0 = std::max(t0, (top_height - oz) / dz);
  else if (dz > 0.0) t1 = std::min(t1, (top_height - oz) / dz);
  if (t0 >= t1) return miss;

  double t = t0;
  // Grid coordinates are non-negative here, so truncation is floor (and avoids a libm call).
  int ix = std::clamp(static_cast<int>(ox + t * dx), 0, cells - 1);
  int iy = std::clamp(static_cast<int>(oy + t * dy), 0, cells - 1);
  // Starting below the root saves descents; rays rarely clear nodes larger than this.
  int level = std::min(top, kStartLevel);
  const double inv_dx = dx != 0.0 ? 1.0 / dx : inf, inv_dy = dy != 0.0 ? 1.0 / dy : inf;
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
    if (below) {
      // Exact intersection with the cell's two triangles, split along its (0,0)-(1,1) diagonal.
      const double h00 = H(ix, iy), h10 = H(ix + 1, iy), h01 = H(ix, iy + 1), h11 = H(ix + 1, iy + 1);
      const double lx = ox - ix, ly = oy - iy;
      double best = inf;
      Eigen::Vector3d normal;
      for (int tri = 0; tri < 2; ++tri) {
        const double a = tri == 0 ? h10 - h00 : h11 - h01, b = tri == 0 ? h11 - h10 : h01 - h00;
        const double denom = dz - a * dx - b * dy;
        if (denom == 0.0) continue;
        const double th = (h00 + a * lx + b * ly - oz) / denom;
        if (th < t - 1e-9 || th > t_exit + 1e-9 || th >= best || th <= 0.0) continue;
        const double u = lx + th * dx, v = ly + th * dy;
        const double tol = 1e-7;
        if (u < -tol || u > 1 + tol || v < -tol || v > 1 + tol) continue;
        if (tri == 0 ? u + tol < v : v + tol < u) continue;
        best = th;
        normal = Eigen::Vector3d(-a / res_, -b / res_, 1.0);
      }
      if (best < inf) return TerrainHit{best, normal.normalized()};
    }
    if (t_exit >= t1) return miss;
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
      if (tx <= ty) return miss;  // left the grid through an x edge
      if (iy < 0 || iy >= cells) return miss;
    }
    ix = std::clamp(ix, 0, cells - 1);
    iy = std::clamp(iy, 0, cells - 1);
    // Climb only into a new parent: re-testing the parent just left would descend again at once.
    if (level < kStartLevel && level < top && ((ix >> (level + 1)) != (cx >> 1) || (iy >> (level + 1)) != (cy >> 1))) {
      ++level;
    }
  }
  return miss;
}

}  // namespace cairn::sim
