#include "drivers/simulator/terrain.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "drivers/simulator/sim_random.h"
#include "drivers/simulator/simd_clones.h"

namespace cairn::sim {
namespace {

// Lattice value in [-1, 1] for integer coordinates of one noise layer.
inline double LatticeValue(uint64_t seed, int64_t ix, int64_t iy, uint64_t layer) {
  const uint64_t h = SimRandom::Mix(seed ^ SimRandom::Mix(static_cast<uint64_t>(ix) * 0x9E3779B97F4A7C15ull ^
                                                          static_cast<uint64_t>(iy) * 0xC2B2AE3D27D4EB4Full ^
                                                          layer * 0x165667B19E3779F9ull));
  return static_cast<double>(h >> 11) * 0x1.0p-52 - 1.0;
}

// Fractal sum of value noise (quintic fade, wavelength 1 in lattice units) from `wavelength` down by
// halves, amplitudes falling with `gain`, sampled on a grid (x = i * step - half for column i, y
// likewise for row j), one row at a time with the rows in increasing order. Every octave's lattice
// values are computed once per lattice point: each octave caches the two lattice rows around the
// current grid row.
class FbmRows {
 public:
  FbmRows(uint64_t seed, int count, double step, double half, double wavelength, int octaves, double gain,
          uint64_t layer)
      : seed_(seed), count_(count), step_(step), half_(half) {
    double amp = 1.0;
    for (int k = 0; k < octaves; ++k) {
      Octave o;
      o.wavelength = wavelength;
      o.amp = amp;
      o.layer = layer * 64 + static_cast<uint64_t>(k);
      // Per column: the lattice column left of the sample and the fade weight towards the right.
      o.column.resize(static_cast<size_t>(count));
      o.fade.resize(static_cast<size_t>(count));
      for (int i = 0; i < count; ++i) {
        const double x = (i * step - half) / wavelength;
        const double fx = std::floor(x);
        const double u = x - fx;
        o.column[static_cast<size_t>(i)] = static_cast<int64_t>(fx);
        o.fade[static_cast<size_t>(i)] = u * u * u * (u * (u * 6 - 15) + 10);
      }
      o.first_column = o.column.front();
      const size_t span = static_cast<size_t>(o.column.back() - o.first_column + 2);
      o.row0.resize(span);
      o.row1.resize(span);
      norm_ += amp;
      amp *= gain;
      wavelength *= 0.5;
      octaves_.push_back(std::move(o));
    }
  }

  void Row(int j, double* out) {
    std::fill(out, out + count_, 0.0);
    for (Octave& o : octaves_) {
      const double y = (j * step_ - half_) / o.wavelength;
      const double fy = std::floor(y);
      const int64_t iy = static_cast<int64_t>(fy);
      const double v = y - fy;
      const double sv = v * v * v * (v * (v * 6 - 15) + 10);
      if (iy != o.cached_row) {
        for (size_t c = 0; c < o.row0.size(); ++c) {
          const int64_t ix = o.first_column + static_cast<int64_t>(c);
          o.row0[c] = LatticeValue(seed_, ix, iy, o.layer);
          o.row1[c] = LatticeValue(seed_, ix, iy + 1, o.layer);
        }
        o.cached_row = iy;
      }
      for (int i = 0; i < count_; ++i) {
        const size_t c = static_cast<size_t>(o.column[static_cast<size_t>(i)] - o.first_column);
        const double su = o.fade[static_cast<size_t>(i)];
        const double a = o.row0[c], b = o.row0[c + 1], cc = o.row1[c], d = o.row1[c + 1];
        out[i] += o.amp * ((a + (b - a) * su) * (1 - sv) + (cc + (d - cc) * su) * sv);
      }
    }
    for (int i = 0; i < count_; ++i) out[i] /= norm_;
  }

 private:
  struct Octave {
    double wavelength = 0.0, amp = 0.0;
    uint64_t layer = 0;
    std::vector<int64_t> column;
    std::vector<double> fade;
    int64_t first_column = 0;
    int64_t cached_row = std::numeric_limits<int64_t>::min();
    std::vector<double> row0, row1;
  };
  uint64_t seed_;
  int count_;
  double step_, half_, norm_ = 0.0;
  std::vector<Octave> octaves_;
};

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
  t.inv_res_ = 1.0 / o.resolution;
  t.n_ = static_cast<int>(std::lround(o.size / o.resolution)) + 1;
  t.seed_ = static_cast<uint64_t>(o.seed);
  const int n = t.n_;
  const double half = t.half_size_, res = t.res_;
  t.h_.assign(static_cast<size_t>(n) * static_cast<size_t>(n), 0.0f);

  // Rolling ground: wavelengths from 24 m down to ~0.4 m.
  {
    FbmRows ground(t.seed_, n, res, half, 24.0, 7, 0.45, 1);
    std::vector<double> row(static_cast<size_t>(n));
    for (int iy = 0; iy < n; ++iy) {
      ground.Row(iy, row.data());
      for (int ix = 0; ix < n; ++ix) {
        t.h_[static_cast<size_t>(iy) * static_cast<size_t>(n) + static_cast<size_t>(ix)] =
            static_cast<float>(o.relief * row[static_cast<size_t>(ix)]);
      }
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

void Terrain::BuildAlbedo(const WorldOptions& o, const std::vector<Eigen::Vector4d>& rocks) {
  tex_res_ = res_ / 4;
  inv_tex_res_ = 1.0 / tex_res_;
  tex_n_ = static_cast<int>(std::lround(2 * half_size_ / tex_res_)) + 1;
  std::vector<float> a(static_cast<size_t>(tex_n_) * static_cast<size_t>(tex_n_));
  // Large patches (regolith colour) and fine grains, with most energy at stereo-relevant scales.
  FbmRows coarse_rows(seed_, tex_n_, tex_res_, half_size_, 8.0, 4, 0.6, 2);
  FbmRows fine_rows(seed_, tex_n_, tex_res_, half_size_, 0.4, 4, 0.7, 3);
  std::vector<double> coarse(static_cast<size_t>(tex_n_)), fine(static_cast<size_t>(tex_n_));
  for (int iy = 0; iy < tex_n_; ++iy) {
    coarse_rows.Row(iy, coarse.data());
    fine_rows.Row(iy, fine.data());
    for (int ix = 0; ix < tex_n_; ++ix) {
      const size_t i = static_cast<size_t>(ix);
      a[static_cast<size_t>(iy) * static_cast<size_t>(tex_n_) + i] =
          static_cast<float>(0.5 + o.albedo_contrast * (0.5 * coarse[i] + 0.9 * fine[i]));
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
