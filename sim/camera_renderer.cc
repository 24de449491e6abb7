#include "sim/camera_renderer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "sim/sim_random.h"
#include "sim/simd_clones.h"

namespace cairn::sim {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// Standard normal values drawn once; pixels index them with cheap random bits.
const std::array<float, 4096>& GaussTable() {
  static const std::array<float, 4096> table = [] {
    std::array<float, 4096> t{};
    SimRandom rng(0x5EED);
    for (float& v : t) v = static_cast<float>(rng.Normal());
    return t;
  }();
  return table;
}

// One scene object reduced to what the pixel loop needs.
struct Object {
  Eigen::Isometry3d T_obj_world;
  Eigen::Vector3d half_extent;   // box; for markers x = y = half edge, z = 0
  bool is_marker = false;
  const SimMarker* marker = nullptr;
  float albedo = 0.3f;
  int u0 = 0, u1 = -1, v0 = 0, v1 = -1;  // pixel rectangle that may see it
  Eigen::Vector3d o_local = Eigen::Vector3d::Zero();  // the camera centre in the object's frame
};

// Pixels share one conservative terrain traversal per tile of kTile x kTile pixels, or half that
// for wide-angle cameras (below kWideFocal px), whose pixels spread faster.
constexpr int kTile = 8;
constexpr double kWideFocal = 700.0;
// Rays per pixel side over markers (their edges are what tag detection measures).
constexpr int kMarkerSamples = 4;

// Distance along the ray to a box in its own frame (slab test) and the hit face normal.
double HitBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& h,
              Eigen::Vector3d* n_local) {
  double t0 = 0.0, t1 = kInf;
  int axis = -1;
  for (int i = 0; i < 3; ++i) {
    if (d[i] == 0.0) {
      if (std::abs(o[i]) > h[i]) return kInf;
      continue;
    }
    double a = (-h[i] - o[i]) / d[i], b = (h[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    if (a > t0) { t0 = a; axis = i; }
    t1 = std::min(t1, b);
    if (t0 > t1) return kInf;
  }
  if (axis < 0) return kInf;  // origin inside the box
  *n_local = Eigen::Vector3d::Zero();
  (*n_local)[axis] = d[axis] > 0 ? -1.0 : 1.0;
  return t0;
}

// Albedo of a marker at local (x, y): quiet ring white, border black, 6 x 6 data bits.
float MarkerAlbedo(const SimMarker& m, double x, double y) {
  const double module = m.size / 8.0, half = 5 * module;
  if (!(std::abs(x) < half && std::abs(y) < half)) return 0.85f;  // beyond the quiet ring (or NaN)
  const int c = static_cast<int>((x + half) / module), r = static_cast<int>((half - y) / module);
  if (r <= 0 || c <= 0 || r >= 9 || c >= 9) return 0.85f;
  if (r == 1 || c == 1 || r == 8 || c == 8) return 0.04f;
  const int bit = (r - 2) * 6 + (c - 2);
  return (m.bits >> (35 - bit)) & 1 ? 0.85f : 0.04f;
}

// One image row's rays, structure of arrays: the world direction, the camera ray's z (inverse
// length of (x, y, 1)), the horizontal length and its inverse (0 for vertical rays), and the
// horizontal components in terrain grid cells.
struct RayRow {
  std::vector<double> dx, dy, dz, inv_len, horizontal, inv_h, gdx, gdy;
};

// Straight-line arithmetic over plain arrays, so that the compiler vectorizes the square roots
// and divisions (the pointers are parameters: restrict-qualified locals do not convince it).
CAIRN_SIM_CLONES void SetUpRays(int w, const double* __restrict xs, double yy1, const double* r0,
                                const double* base, double inv_res, double* __restrict rdx,
                                double* __restrict rdy, double* __restrict rdz, double* __restrict rlen,
                                double* __restrict rhor, double* __restrict rih, double* __restrict rgx,
                                double* __restrict rgy) {
  const double ax = r0[0], ay = r0[1], az = r0[2], bx = base[0], by = base[1], bz = base[2];
  for (int u = 0; u < w; ++u) {
    const double xc = xs[u];
    const double inv_len = 1.0 / std::sqrt(xc * xc + yy1);
    const double dx = (ax * xc + bx) * inv_len, dy = (ay * xc + by) * inv_len, dz = (az * xc + bz) * inv_len;
    const double horizontal = std::sqrt(dx * dx + dy * dy);
    const double inv_h = 1.0 / std::max(horizontal, 1e-9);
    rdx[u] = dx;
    rdy[u] = dy;
    rdz[u] = dz;
    rlen[u] = inv_len;
    rhor[u] = horizontal;
    rih[u] = horizontal > 1e-9 ? inv_h : 0.0;
    rgx[u] = dx * inv_res;
    rgy[u] = dy * inv_res;
  }
}

void SetUpRays(int w, const double* xs, double yc, const Eigen::Vector3d& r0, const Eigen::Vector3d& row_base,
               double inv_res, RayRow* r) {
  SetUpRays(w, xs, yc * yc + 1.0, r0.data(), row_base.data(), inv_res, r->dx.data(), r->dy.data(), r->dz.data(),
            r->inv_len.data(), r->horizontal.data(), r->inv_h.data(), r->gdx.data(), r->gdy.data());
}

// The column bound from the pixel straight below, for a span of a row (straight-line code over
// arrays, vectorized): where the image of the vertical runs within half a pixel of straight down
// (|fx (nx - x nz)| < down_v / 2) and the lower ray met the terrain, the height gap between the
// rays must outgrow what the steepest slope makes of the sideways gap (see RenderSignal). Also
// stores this row's ray slopes and directions, its hits not yet known.
CAIRN_SIM_CLONES void ColumnBound(int n, bool enabled, double slope2, double fx_nx, double fx_nz,
                                  double half_down_v, const double* __restrict xs, const double* __restrict dxs,
                                  const double* __restrict dys, const double* __restrict dzs,
                                  const double* __restrict inv_hs, const double* __restrict rho_a,
                                  const double* __restrict tan_a, const double* __restrict hx_a,
                                  const double* __restrict hy_a, double* __restrict tan_b, double* __restrict hx_b,
                                  double* __restrict hy_b, double* __restrict rho_b, double* __restrict t_start,
                                  double* __restrict bounded) {
  for (int i = 0; i < n; ++i) {
    const double inv_h = inv_hs[i];
    const double tan_e = dzs[i] * inv_h, hx = dxs[i] * inv_h, hy = dys[i] * inv_h;
    tan_b[i] = tan_e;
    hx_b[i] = hx;
    hy_b[i] = hy;
    rho_b[i] = -1.0;
    const double rise = tan_e - tan_a[i];
    const double ex = hx - hx_a[i], ey = hy - hy_a[i];
    const bool ok = enabled & (inv_h > 0.0) & (rho_a[i] > 0.0) & (std::abs(fx_nx - xs[i] * fx_nz) < half_down_v) &
                    (rise > 0.0) & (rise * rise >= slope2 * (ex * ex + ey * ey) * (1.0 + 1e-9) + 1e-300);
    t_start[i] = ok ? rho_a[i] * inv_h * (1.0 - 1e-10) : 0.0;
    bounded[i] = ok ? 1.0 : 0.0;
  }
}

// Shading of terrain hits, for a span of a row (vectorized): the hit triangle's unit normal
// against the sun, and where the ray met the terrain (for rays that did not, the values go unused).
CAIRN_SIM_CLONES void ShadeSpan(int n, const Terrain::CellHit* __restrict hits, double inv_res, const double* sun,
                                double ambient, double ox, double oy, const double* __restrict dxs,
                                const double* __restrict dys, double* __restrict shade, double* __restrict hit_x,
                                double* __restrict hit_y) {
  const double sx = sun[0], sy = sun[1], sz = sun[2];
  for (int i = 0; i < n; ++i) {
    const double nx = -hits[i].a * inv_res, ny = -hits[i].b * inv_res;
    const double inv_norm = 1.0 / std::sqrt(nx * nx + ny * ny + 1.0);
    shade[i] = ambient + std::max(0.0, (nx * inv_norm) * sx + (ny * inv_norm) * sy + inv_norm * sz);
    hit_x[i] = ox + hits[i].t * dxs[i];
    hit_y[i] = oy + hits[i].t * dys[i];
  }
}

}  // namespace

void RenderScene::AddRobot(const SimRobot& robot, const Eigen::Isometry3d& T_world_body) {
  for (SimBox b : robot.boxes) {
    b.T_body_box = T_world_body * b.T_body_box;
    boxes.push_back(b);
  }
  for (SimMarker m : robot.markers) {
    m.T_body_marker = T_world_body * m.T_body_marker;
    markers.push_back(m);
  }
}

void CameraRenderer::Render(const RenderScene& scene, const PinholeRadTan& k,
                            const Eigen::Isometry3d& T_world_cam, const RenderOptions& options,
                            uint64_t noise_seed, std::vector<uint8_t>* image,
                            std::vector<float>* depth) {
  std::vector<float> signal;
  RenderSignal(scene, k, T_world_cam, options, &signal, depth);
  ApplyNoise(signal, k.width, options, noise_seed, image);
}

CAIRN_SIM_CLONES void CameraRenderer::ApplyNoise(const std::vector<float>& signal, int width,
                                                 const RenderOptions& options, uint64_t noise_seed,
                                                 std::vector<uint8_t>* image) {
  const auto& gauss = GaussTable();
  image->resize(signal.size());
  const size_t w = static_cast<size_t>(width);
  std::vector<float> g(w);
  const double read_var = options.read_noise * options.read_noise, shot = options.shot_noise;
  for (size_t row = 0; row * w < signal.size(); ++row) {
    // One stream per row: 12 random bits per pixel pick a standard normal value from the table.
    SimRandom rng = SimRandom::Stream(noise_seed, row);
    uint64_t bits = 0;
    int bits_left = 0;
    for (size_t i = 0; i < w; ++i) {
      if (bits_left < 12) {
        bits = rng.Next();
        bits_left = 64;
      }
      g[i] = gauss[bits & 4095];
      bits >>= 12;
      bits_left -= 12;
    }
    // Read noise plus shot noise, then quantization (vectorizable).
    const float* __restrict s = signal.data() + row * w;
    uint8_t* __restrict out = image->data() + row * w;
    const float* __restrict gp = g.data();
    for (size_t i = 0; i < w; ++i) {
      const double sigma = std::sqrt(read_var + shot * s[i]);
      const double value = std::min(std::max(s[i] + sigma * gp[i], 0.0), 255.0);
      out[i] = static_cast<uint8_t>(value + 0.5);
    }
  }
}

void CameraRenderer::RenderSignal(const RenderScene& scene, const PinholeRadTan& k,
                                  const Eigen::Isometry3d& T_world_cam, const RenderOptions& options,
                                  std::vector<float>* out, std::vector<float>* depth) {
  const int w = k.width, h = k.height;
  out->resize(static_cast<size_t>(w) * static_cast<size_t>(h));  // every pixel is written below
  if (depth != nullptr) depth->assign(out->size(), 0.0f);
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Eigen::Matrix3d R = T_world_cam.linear();
  const Eigen::Vector3d origin = T_world_cam.translation();

  // Objects with the pixel rectangle that can see them: the bounds of the projection of the part
  // of their box in front of the camera (a box reaching behind the camera is unbounded towards
  // the side where it crosses the camera's plane).
  std::vector<Object> objects;
  auto add = [&](const Eigen::Isometry3d& T_world_obj, const Eigen::Vector3d& half, bool marker,
                 const SimMarker* m, float albedo) {
    Object ob{T_world_obj.inverse(), half, marker, m, albedo};
    ob.o_local = ob.T_obj_world * origin;
    // The pixel tests never hit a box from inside (a robot's camera within its own body) nor a
    // marker from behind.
    if (marker ? ob.o_local.z() <= 0.0 : (ob.o_local.cwiseAbs().array() <= half.array()).all()) return;
    const Eigen::Isometry3d T_cam_obj = T_cam_world * T_world_obj;
    const Eigen::Vector3d pad = half + Eigen::Vector3d::Constant(1e-3);
    std::array<Eigen::Vector3d, 8> c;
    for (int i = 0; i < 8; ++i) {
      c[static_cast<size_t>(i)] = T_cam_obj * Eigen::Vector3d(i & 1 ? pad.x() : -pad.x(), i & 2 ? pad.y() : -pad.y(),
                                                              i & 4 ? pad.z() : -pad.z());
    }
    double umin = kInf, umax = -kInf, vmin = kInf, vmax = -kInf;
    bool in_front = false;
    for (const Eigen::Vector3d& p : c) {
      if (p.z() <= 0.0) continue;
      in_front = true;
      const double u = k.fx * p.x() / p.z() + k.cx, v = k.fy * p.y() / p.z() + k.cy;
      umin = std::min(umin, u); umax = std::max(umax, u);
      vmin = std::min(vmin, v); vmax = std::max(vmax, v);
    }
    if (!in_front) return;  // wholly behind the camera
    for (int i = 0; i < 8; ++i) {
      for (int bit = 1; bit < 8; bit <<= 1) {
        const int j = i | bit;
        if (j == i) continue;
        const Eigen::Vector3d& a = c[static_cast<size_t>(i)];
        const Eigen::Vector3d& b = c[static_cast<size_t>(j)];
        if ((a.z() > 0.0) == (b.z() > 0.0)) continue;
        // The edge crosses the camera's plane at q: points just in front of it project towards
        // infinity in the direction of q's (x, y).
        const Eigen::Vector3d q = a + (b - a) * (a.z() / (a.z() - b.z()));
        constexpr double kTiny = 1e-9;
        if (q.x() > -kTiny) umax = kInf;
        if (q.x() < kTiny) umin = -kInf;
        if (q.y() > -kTiny) vmax = kInf;
        if (q.y() < kTiny) vmin = -kInf;
      }
    }
    const double lo_u = std::max(umin, -1.0), hi_u = std::min(umax, static_cast<double>(w));
    const double lo_v = std::max(vmin, -1.0), hi_v = std::min(vmax, static_cast<double>(h));
    ob.u0 = std::max(0, static_cast<int>(std::floor(lo_u)) - 1);
    ob.u1 = std::min(w - 1, static_cast<int>(std::ceil(hi_u)) + 1);
    ob.v0 = std::max(0, static_cast<int>(std::floor(lo_v)) - 1);
    ob.v1 = std::min(h - 1, static_cast<int>(std::ceil(hi_v)) + 1);
    if (ob.u0 <= ob.u1 && ob.v0 <= ob.v1) objects.push_back(ob);
  };
  for (const SimBox& b : scene.boxes) add(b.T_body_box, b.half_extent, false, nullptr, b.albedo);
  for (const SimMarker& m : scene.markers) {
    add(m.T_body_marker, Eigen::Vector3d(m.size * 0.625, m.size * 0.625, 0.0), true, &m, 0.0f);
  }

  const double scale = options.gain * options.exposure * 255.0;
  const Eigen::Vector3d& sun = scene.sun_direction;
  const Terrain& terrain = *scene.terrain;
  // Ray directions: the world direction of pixel (u, v) is (r0 x_u + r1 y_v + r2) / |(x_u, y_v, 1)|.
  std::vector<double> col_x(static_cast<size_t>(w)), row_y(static_cast<size_t>(h));
  for (int u = 0; u < w; ++u) col_x[static_cast<size_t>(u)] = (u - k.cx) / k.fx;
  for (int v = 0; v < h; ++v) row_y[static_cast<size_t>(v)] = (v - k.cy) / k.fy;
  const Eigen::Vector3d r0 = R.col(0), r1 = R.col(1), r2 = R.col(2);
  auto world_ray = [&](double x, double y) {
    return Eigen::Vector3d((r0 * x + r1 * y + r2) * (1.0 / std::sqrt(x * x + y * y + 1.0)));
  };

  // Per tile of pixels, one conservative traversal for the tile's bundle of rays:
  // none of them meets the terrain before the tile's clear distance.
  const int tile = std::min(k.fx, k.fy) < kWideFocal ? kTile / 2 : kTile;
  const int tiles_x = (w + tile - 1) / tile;
  std::vector<double> tile_clear(static_cast<size_t>(tiles_x));
  int tile_row = -1;  // the row of tiles that tile_clear is for; its entries are computed on demand
  auto tile_clear_at = [&](int u) {
    const int tv0 = tile_row * tile, tv1 = std::min(h, tv0 + tile) - 1;
    const size_t tx = static_cast<size_t>(u / tile);
    if (!(tile_clear[tx] >= 0.0)) {
      const int tu0 = static_cast<int>(tx) * tile, tu1 = std::min(w, tu0 + tile) - 1;
      const double xm = 0.5 * (col_x[static_cast<size_t>(tu0)] + col_x[static_cast<size_t>(tu1)]);
      const double ym = 0.5 * (row_y[static_cast<size_t>(tv0)] + row_y[static_cast<size_t>(tv1)]);
      const Eigen::Vector3d centre = world_ray(xm, ym);
      double spread = 0.0;
      for (const int cu : {tu0, tu1}) {
        for (const int cv : {tv0, tv1}) {
          const Eigen::Vector3d corner = world_ray(col_x[static_cast<size_t>(cu)], row_y[static_cast<size_t>(cv)]);
          spread = std::max(spread, (corner - centre).norm());
        }
      }
      tile_clear[tx] = terrain.ClearDistance(origin, centre, spread, options.max_range);
    }
    return tile_clear[tx];
  };

  // The column bound. The ray of pixel B and the ray of a pixel A in a row below it, compared at
  // equal horizontal distance rho, are rho |hB - hA| apart sideways (h: unit horizontal
  // directions) and rho (tanB - tanA) apart in height (tan: slope of the ray). Where the height
  // gap outgrows what the steepest terrain slope can make up over the sideways gap, B stays above
  // the terrain for as long as A did: up to A's hit. A is the pixel straight below B in the image
  // when the camera looks ahead; a steep camera's vertical planes fan out from the nadir's image,
  // so A is then taken up to kBelowRows rows down along that direction.
  const double slope = terrain.max_slope();
  const bool origin_on_grid =
      std::abs(origin.x()) <= terrain.half_size() && std::abs(origin.y()) <= terrain.half_size();
  // Per pixel of the last kBelowRows + 1 rows (a ring): the horizontal distance of its terrain
  // hit (< 0: none), the slope of its ray and the ray's unit horizontal direction.
  constexpr int kBelowRows = 4;
  struct Columns {
    double* rho;
    double* tan_elevation;
    double* hx;
    double* hy;
  };
  std::vector<double> history(4 * static_cast<size_t>(kBelowRows + 1) * static_cast<size_t>(w), -1.0);
  auto history_row = [&](int row) {
    double* base = history.data() + 4 * static_cast<size_t>(row % (kBelowRows + 1)) * static_cast<size_t>(w);
    const size_t ws = static_cast<size_t>(w);
    return Columns{base, base + ws, base + 2 * ws, base + 3 * ws};
  };
  // The nadir in camera coordinates: at pixel (u, v) the image of "down" points along
  // (fx (nx - x nz), fy (ny - y nz)) for the camera ray (x, y, 1).
  const Eigen::Vector3d nadir = -R.row(2).transpose();

  // One image row at a time, bottom-up (so that the pixels below are done), in spans of up to
  // kSpan pixels that keep their working arrays in the first-level cache, and in passes: ray set-up
  // (divisions and square roots, vectorized), objects and search bounds, the search, shading.
  constexpr int kSpan = 128;
  RayRow rays;
  for (auto* vec : {&rays.dx, &rays.dy, &rays.dz, &rays.inv_len, &rays.horizontal, &rays.inv_h, &rays.gdx,
                    &rays.gdy}) {
    vec->resize(kSpan);
  }
  enum class Seen : uint8_t { kSky, kTerrain, kObject };
  std::array<Seen, kSpan> seen{};
  std::array<Terrain::CellHit, kSpan> hits{};
  std::array<double, kSpan> object_signal{}, shade{}, t_max{}, t_start{}, hit_x{}, hit_y{}, bounded{};
  std::array<float, kSpan> albedo{};
  bool found[kSpan] = {};
  std::vector<const Object*> row_objects;
  const double inv_res = 1.0 / terrain.resolution();
  const double gox = (origin.x() + terrain.half_size()) * inv_res, goy = (origin.y() + terrain.half_size()) * inv_res;
  for (int v = h - 1; v >= 0; --v) {
    if (v / tile != tile_row) {
      tile_row = v / tile;
      std::fill(tile_clear.begin(), tile_clear.end(), -1.0);
    }
    const double yc = row_y[static_cast<size_t>(v)];
    const Eigen::Vector3d row_base = r1 * yc + r2;
    const Columns current = history_row(v);
    // (Ring rows past the bottom of the image hold no hits.)
    Columns below_rows[kBelowRows + 1] = {};
    for (int m = 1; m <= kBelowRows; ++m) below_rows[m] = history_row(v + m);
    const int rows_below = std::min(kBelowRows, h - 1 - v);
    const bool column_bound = rows_below > 0 && origin_on_grid;
    row_objects.clear();
    for (const Object& ob : objects) {
      if (v >= ob.v0 && v <= ob.v1) row_objects.push_back(&ob);
    }
    const double down_v = k.fy * (nadir.y() - yc * nadir.z());
    float* out_row = out->data() + static_cast<size_t>(v) * static_cast<size_t>(w);
    float* depth_row = depth != nullptr ? depth->data() + static_cast<size_t>(v) * static_cast<size_t>(w) : nullptr;
    for (int u0 = 0; u0 < w; u0 += kSpan) {
      const int n = std::min(kSpan, w - u0);
      SetUpRays(n, col_x.data() + u0, yc, r0, row_base, inv_res, &rays);
      // Objects first: they bound the terrain search.
      if (row_objects.empty()) {
        std::fill_n(seen.begin(), n, Seen::kSky);
        std::fill_n(t_max.begin(), n, options.max_range);
      } else {
        for (int i = 0; i < n; ++i) {
          const int u = u0 + i;
          const size_t j = static_cast<size_t>(i);
          const Eigen::Vector3d dir(rays.dx[j], rays.dy[j], rays.dz[j]);
          double t_best = options.max_range;
          double object_albedo = 0.0;
          Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
          seen[j] = Seen::kSky;
          for (const Object* obp : row_objects) {
            const Object& ob = *obp;
            if (u < ob.u0 || u > ob.u1) continue;
            const Eigen::Vector3d& o = ob.o_local;
            const Eigen::Vector3d d = ob.T_obj_world.linear() * dir;
            if (ob.is_marker) {
              if (d.z() >= 0.0 || o.z() <= 0.0) continue;  // seen from behind or edge-on
              const double t = -o.z() / d.z();
              const Eigen::Vector3d p = o + t * d;
              if (t >= t_best || std::abs(p.x()) > ob.half_extent.x() || std::abs(p.y()) > ob.half_extent.y()) continue;
              t_best = t;
              // A pixel integrates light over its area: averaging 4 x 4 rays through it puts the
              // marker's inner edges where they are to a fraction of a pixel (one ray would snap
              // them to pixel boundaries, half a pixel off at worst).
              float sum = 0.0f;
              for (int sv = 0; sv < kMarkerSamples; ++sv) {
                for (int su = 0; su < kMarkerSamples; ++su) {
                  const double du = (su + 0.5) / kMarkerSamples - 0.5, dv = (sv + 0.5) / kMarkerSamples - 0.5;
                  const Eigen::Vector3d ds = ob.T_obj_world.linear() * world_ray(col_x[static_cast<size_t>(u)] + du / k.fx,
                                                                                 yc + dv / k.fy);
                  // A sub-ray that does not meet the marker's plane in front (grazing view)
                  // takes the pixel centre's value.
                  if (!(ds.z() < -1e-9)) {
                    sum += MarkerAlbedo(*ob.marker, p.x(), p.y());
                    continue;
                  }
                  const Eigen::Vector3d ps = o + (-o.z() / ds.z()) * ds;
                  sum += MarkerAlbedo(*ob.marker, ps.x(), ps.y());
                }
              }
              object_albedo = sum / (kMarkerSamples * kMarkerSamples);
              normal = ob.T_obj_world.linear().transpose() * Eigen::Vector3d::UnitZ();
              seen[j] = Seen::kObject;
            } else {
              Eigen::Vector3d n_local;
              const double t = HitBox(o, d, ob.half_extent, &n_local);
              if (t >= t_best) continue;
              t_best = t;
              object_albedo = ob.albedo;
              normal = ob.T_obj_world.linear().transpose() * n_local;
              seen[j] = Seen::kObject;
            }
          }
          if (seen[j] == Seen::kObject) {
            object_signal[j] = scale * object_albedo * (options.ambient + std::max(0.0, normal.dot(sun)));
          }
          t_max[j] = t_best;
        }
      }
      // Then where the terrain search starts: the column bound from the pixel straight below where
      // that is the one (vectorized), else from one further down along the image of the vertical,
      // else the tile's clear distance.
      ColumnBound(n, column_bound && down_v > 0.0, slope * slope, k.fx * nadir.x(), k.fx * nadir.z(), 0.5 * down_v,
                  col_x.data() + u0, rays.dx.data(), rays.dy.data(), rays.dz.data(), rays.inv_h.data(),
                  below_rows[1].rho + u0, below_rows[1].tan_elevation + u0, below_rows[1].hx + u0,
                  below_rows[1].hy + u0, current.tan_elevation + u0, current.hx + u0, current.hy + u0,
                  current.rho + u0, t_start.data(), bounded.data());
      for (int i = 0; i < n; ++i) {
        const size_t j = static_cast<size_t>(i);
        if (bounded[j] != 0.0) continue;
        const int u = u0 + i;
        const double inv_h = rays.inv_h[j];
        const double tan_e = current.tan_elevation[u], hx = current.hx[u], hy = current.hy[u];
        bool found_bound = false;
        if (column_bound && down_v > 0.0 && inv_h > 0.0) {
          const double down_u = k.fx * (nadir.x() - col_x[static_cast<size_t>(u)] * nadir.z());
          for (int m = 1; m <= rows_below && !found_bound; ++m) {
            const double shift = m * down_u;  // columns to the pixel m rows down, times down_v
            const int ua = 2.0 * std::abs(shift) < down_v ? u : u + static_cast<int>(std::lround(shift / down_v));
            if (ua < 0 || ua >= w) break;
            const Columns& a = below_rows[m];
            if (!(a.rho[ua] > 0.0)) continue;
            const double rise = tan_e - a.tan_elevation[ua];
            const double ex = hx - a.hx[ua], ey = hy - a.hy[ua];
            if (rise > 0.0 && rise * rise >= slope * slope * (ex * ex + ey * ey) * (1.0 + 1e-9) + 1e-300) {
              t_start[j] = a.rho[ua] * inv_h * (1.0 - 1e-10);
              found_bound = true;
            }
          }
        }
        if (!found_bound) t_start[j] = tile_clear_at(u);
      }
      const Terrain::RayBatch batch{gox, goy, origin.z(), n, rays.gdx.data(), rays.gdy.data(), rays.dz.data(),
                                    t_max.data(), t_start.data()};
      terrain.TraceRays(batch, hits.data(), found);
      for (int i = 0; i < n; ++i) {
        const size_t j = static_cast<size_t>(i);
        if (found[j]) {
          seen[j] = Seen::kTerrain;
          if (rays.inv_h[j] > 0.0) current.rho[u0 + i] = hits[j].t * rays.horizontal[j];
        } else if (seen[j] == Seen::kObject) {
          hits[j].t = t_max[j];
        }
      }
      ShadeSpan(n, hits.data(), inv_res, sun.data(), options.ambient, origin.x(), origin.y(), rays.dx.data(),
                rays.dy.data(), shade.data(), hit_x.data(), hit_y.data());
      terrain.Albedo(n, hit_x.data(), hit_y.data(), albedo.data());
      for (int i = 0; i < n; ++i) {
        const size_t j = static_cast<size_t>(i);
        double signal = 0.0;
        if (seen[j] == Seen::kTerrain) {
          signal = scale * albedo[j] * shade[j];
        } else if (seen[j] == Seen::kObject) {
          signal = object_signal[j];
        }
        if (seen[j] != Seen::kSky && depth_row != nullptr) {
          depth_row[u0 + i] = static_cast<float>(hits[j].t * rays.inv_len[j]);  // z of the hit
        }
        out_row[u0 + i] = static_cast<float>(signal);
      }
    }
  }
}

}  // namespace cairn::sim
