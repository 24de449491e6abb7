#include "sim/terrain_generator.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numbers>
#include <utility>
#include <vector>

#include "sim/sim_random.h"

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

// Coordinates of (x, y) in a structure's own frame (along its length, its width), and whether they
// lie on its footprint.
Eigen::Vector2d StructureLocal(const double* b, double x, double y) {
  const double yaw = b[2] * std::numbers::pi / 180.0;
  const double dx = x - b[0], dy = y - b[1];
  return {std::cos(yaw) * dx + std::sin(yaw) * dy, -std::sin(yaw) * dx + std::cos(yaw) * dy};
}
bool OnFootprint(const double* b, const Eigen::Vector2d& local) {
  return std::abs(local.x()) <= b[3] / 2 && std::abs(local.y()) <= b[4] / 2;
}

// Calls f(ix, iy, local) for every sample of a grid of `count` x `count` samples `step` apart from
// -half that lies on a structure's footprint (local: its coordinates in the structure's frame).
template <class F>
void ForEachOnFootprint(const double* b, double half, double step, int count, F&& f) {
  const double reach = std::hypot(b[3], b[4]) / 2;
  const int x0 = std::max(0, static_cast<int>(std::floor((b[0] - reach + half) / step)));
  const int x1 = std::min(count - 1, static_cast<int>(std::ceil((b[0] + reach + half) / step)));
  const int y0 = std::max(0, static_cast<int>(std::floor((b[1] - reach + half) / step)));
  const int y1 = std::min(count - 1, static_cast<int>(std::ceil((b[1] + reach + half) / step)));
  for (int iy = y0; iy <= y1; ++iy) {
    for (int ix = x0; ix <= x1; ++ix) {
      const Eigen::Vector2d local = StructureLocal(b, ix * step - half, iy * step - half);
      if (OnFootprint(b, local)) f(ix, iy, local);
    }
  }
}

}  // namespace

TerrainGrids TerrainGenerator::Generate(const WorldOptions& o) {
  TerrainGrids t;
  t.half_size = o.size / 2;
  t.resolution = o.resolution;
  t.n = static_cast<int>(std::lround(o.size / o.resolution)) + 1;
  const uint64_t seed = static_cast<uint64_t>(o.seed);
  const int n = t.n;
  const double half = t.half_size, res = t.resolution;
  t.heights.assign(static_cast<size_t>(n) * static_cast<size_t>(n), 0.0f);

  // Rolling ground: wavelengths from 24 m down to ~0.4 m.
  {
    FbmRows ground(seed, n, res, half, 24.0, 7, 0.45, 1);
    std::vector<double> row(static_cast<size_t>(n));
    for (int iy = 0; iy < n; ++iy) {
      ground.Row(iy, row.data());
      for (int ix = 0; ix < n; ++ix) {
        t.heights[static_cast<size_t>(iy) * static_cast<size_t>(n) + static_cast<size_t>(ix)] =
            static_cast<float>(o.relief * row[static_cast<size_t>(ix)]);
      }
    }
  }
  SimRandom rng = SimRandom::Stream(seed, 17);
  const double hectares = o.size * o.size / 1e4;
  // Small craters: bowl with a raised rim, more small ones than large ones.
  const int craters = static_cast<int>(std::lround(o.crater_density * hectares));
  for (int i = 0; i < craters; ++i) {
    const double cx = rng.Uniform(-half, half), cy = rng.Uniform(-half, half);
    const double r = 0.5 * std::pow(8.0, rng.Uniform() * rng.Uniform());
    const double depth = 0.18 * r, rim = 0.05 * r;
    Stamp(t.heights, n, half, res, cx, cy, r, 2.0, [&](double s) {
      return s < 1.0 ? depth * (s * s - 1.0) + rim * s * s * s * s : rim * std::exp(-(s - 1.0) * (s - 1.0) / 0.08);
    });
  }
  // One large crater with steep inner walls: a cliff-like negative edge for the classifier.
  if (o.big_crater) {
    const double r = std::min(10.0, o.size / 6);
    double cx = rng.Uniform(-half / 2, half / 2), cy = rng.Uniform(-half / 2, half / 2);
    // A lander does not set down in it: its wall stays clear of the landing site (redrawn,
    // a bounded number of times, while it is not).
    for (int k = 0; k < 64 && o.lander.size() == 2 &&
                    std::hypot(cx - o.lander[0], cy - o.lander[1]) < r + 1.5 * o.landing_site;
         ++k) {
      cx = rng.Uniform(-half / 2, half / 2);
      cy = rng.Uniform(-half / 2, half / 2);
    }
    const double depth = 0.3 * r, rim = 0.08 * r;
    Stamp(t.heights, n, half, res, cx, cy, r, 1.8, [&](double s) {
      const double s8 = std::pow(s, 8.0);
      return s < 1.0 ? depth * (s8 - 1.0) + rim * s8 : rim * std::exp(-(s - 1.0) * (s - 1.0) / 0.05);
    });
  }
  // The landing site: a lander sets down on level ground, so robots deployed from it stand level
  // in front of its tags. Flat within the radius at the height of its centre, blending into the
  // terrain beyond (smoothstep over another half radius).
  const bool site = o.lander.size() == 2 && o.landing_site > 0.0;
  const double sx = site ? o.lander[0] : 0.0, sy = site ? o.lander[1] : 0.0;
  if (site) {
    const int cx = std::clamp(static_cast<int>(std::lround((sx + half) / res)), 0, n - 1);
    const int cy = std::clamp(static_cast<int>(std::lround((sy + half) / res)), 0, n - 1);
    const float level = t.heights[static_cast<size_t>(cy) * static_cast<size_t>(n) + static_cast<size_t>(cx)];
    const double r = o.landing_site;
    const int x0 = std::max(0, static_cast<int>(std::floor((sx - 1.5 * r + half) / res)));
    const int x1 = std::min(n - 1, static_cast<int>(std::ceil((sx + 1.5 * r + half) / res)));
    const int y0 = std::max(0, static_cast<int>(std::floor((sy - 1.5 * r + half) / res)));
    const int y1 = std::min(n - 1, static_cast<int>(std::ceil((sy + 1.5 * r + half) / res)));
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) {
        const double s = std::hypot(ix * res - half - sx, iy * res - half - sy) / r;
        const double u = std::clamp((1.5 - s) / 0.5, 0.0, 1.0);
        const double w = u * u * (3.0 - 2.0 * u);
        float& h = t.heights[static_cast<size_t>(iy) * static_cast<size_t>(n) + static_cast<size_t>(ix)];
        h = static_cast<float>((1.0 - w) * h + w * level);
      }
    }
  }
  // Boulders: hemispheroids standing on the ground (positive steps); none on the landing site.
  std::vector<Eigen::Vector4d> rocks;
  const int rock_count = static_cast<int>(std::lround(o.rock_density * hectares));
  for (int i = 0; i < rock_count; ++i) {
    const double cx = rng.Uniform(-half, half), cy = rng.Uniform(-half, half);
    const double r = o.rock_size * 0.05 * std::pow(10.0, rng.Uniform() * rng.Uniform());
    const double hr = r * rng.Uniform(0.5, 0.9);
    if (site && std::hypot(cx - sx, cy - sy) < o.landing_site + r) continue;
    rocks.emplace_back(cx, cy, r, hr);
    Stamp(t.heights, n, half, res, cx, cy, r, 1.0, [&](double s) { return hr * std::sqrt(std::max(0.0, 1.0 - s * s)); });
  }
  // Structures: every vertex on the footprint at one level, so the sides are as steep as the grid
  // allows (one cell) and the top is flat.
  for (size_t i = 0; i + WorldOptions::kStructureValues <= o.structures.size();
       i += WorldOptions::kStructureValues) {
    const double* b = &o.structures[i];
    float ground = std::numeric_limits<float>::infinity();
    std::vector<size_t> on;
    ForEachOnFootprint(b, half, res, n, [&](int ix, int iy, const Eigen::Vector2d&) {
      const size_t k = static_cast<size_t>(iy) * static_cast<size_t>(n) + static_cast<size_t>(ix);
      on.push_back(k);
      ground = std::min(ground, t.heights[k]);
    });
    for (const size_t k : on) t.heights[k] = ground + static_cast<float>(b[5]);
  }
  BuildAlbedo(o, rocks, &t);
  return t;
}

void TerrainGenerator::BuildAlbedo(const WorldOptions& o, const std::vector<Eigen::Vector4d>& rocks,
                                   TerrainGrids* t) {
  const uint64_t seed = static_cast<uint64_t>(o.seed);
  const double half_size = t->half_size;
  const double tex_res = t->resolution / 4;
  const int tex_n = static_cast<int>(std::lround(2 * half_size / tex_res)) + 1;
  t->texture_resolution = tex_res;
  t->texture_n = tex_n;
  std::vector<float> a(static_cast<size_t>(tex_n) * static_cast<size_t>(tex_n));
  // Large patches (regolith colour) and fine grains, with most energy at stereo-relevant scales.
  FbmRows coarse_rows(seed, tex_n, tex_res, half_size, 8.0, 4, 0.6, 2);
  FbmRows fine_rows(seed, tex_n, tex_res, half_size, 0.4, 4, 0.7, 3);
  std::vector<double> coarse(static_cast<size_t>(tex_n)), fine(static_cast<size_t>(tex_n));
  for (int iy = 0; iy < tex_n; ++iy) {
    coarse_rows.Row(iy, coarse.data());
    fine_rows.Row(iy, fine.data());
    for (int ix = 0; ix < tex_n; ++ix) {
      const size_t i = static_cast<size_t>(ix);
      a[static_cast<size_t>(iy) * static_cast<size_t>(tex_n) + i] =
          static_cast<float>(0.5 + o.albedo_contrast * (0.5 * coarse[i] + 0.9 * fine[i]));
    }
  }
  // Rocks are darker than the regolith around them.
  for (const Eigen::Vector4d& r : rocks) {
    const int x0 = std::max(0, static_cast<int>((r[0] - r[2] + half_size) / tex_res));
    const int x1 = std::min(tex_n - 1, static_cast<int>((r[0] + r[2] + half_size) / tex_res) + 1);
    const int y0 = std::max(0, static_cast<int>((r[1] - r[2] + half_size) / tex_res));
    const int y1 = std::min(tex_n - 1, static_cast<int>((r[1] + r[2] + half_size) / tex_res) + 1);
    for (int iy = y0; iy <= y1; ++iy) {
      for (int ix = x0; ix <= x1; ++ix) {
        const double dx = ix * tex_res - half_size - r[0], dy = iy * tex_res - half_size - r[1];
        if (dx * dx + dy * dy < r[2] * r[2]) a[static_cast<size_t>(iy) * static_cast<size_t>(tex_n) + static_cast<size_t>(ix)] *= 0.75f;
      }
    }
  }
  // Structures are painted panels, lighter than the regolith, with darker joints every metre along
  // both axes; the speckle of their paint gives stereo something to match on sides and tops.
  for (size_t s = 0; s + WorldOptions::kStructureValues <= o.structures.size();
       s += WorldOptions::kStructureValues) {
    const double* b = &o.structures[s];
    ForEachOnFootprint(b, half_size, tex_res, tex_n, [&](int ix, int iy, const Eigen::Vector2d& l) {
      const double speckle = LatticeValue(seed, ix, iy, 11);
      const double ju = std::abs(l.x() + b[3] / 2 - std::round(l.x() + b[3] / 2));
      const double jv = std::abs(l.y() + b[4] / 2 - std::round(l.y() + b[4] / 2));
      const bool joint = std::min(ju, jv) < 0.03;
      a[static_cast<size_t>(iy) * static_cast<size_t>(tex_n) + static_cast<size_t>(ix)] =
          static_cast<float>((0.7 + 0.15 * speckle) * (joint ? 0.55 : 1.0));
    });
  }
  t->grain.resize(256 * 256);
  for (size_t i = 0; i < t->grain.size(); ++i) {
    t->grain[i] = static_cast<float>(LatticeValue(seed, static_cast<int64_t>(i & 255), static_cast<int64_t>(i >> 8), 9));
  }
  t->albedo.resize(a.size());
  for (size_t i = 0; i < a.size(); ++i) {
    t->albedo[i] = static_cast<uint8_t>(std::clamp(std::lround(a[i] * 255.0f), 0l, 255l));
  }
}

}  // namespace cairn::sim
