#include "mapping/line_segment_detector.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <cstring>

namespace cairn {
namespace {

// The smoothed image holds 256 times the gray value; the Sobel kernel sums four central
// differences (8 times the gradient), shifted right by 4: 128 gradient units per DN/px.
constexpr float kLineSobelScale = 128.0f;
constexpr int kLineGradientShift = 4;
// Pixels this close to the border have no gradient (binomial 5 x 5 and Sobel 3 x 3).
constexpr int kLineBorder = 3;
// Magnitude buckets of the strongest-first seed order (the magnitude reaches about 23100).
constexpr int kLineSeedBuckets = 1024;
constexpr float kLineMaxSobel = 23100.0f;
// Shortest piece that is fitted and may be joined to a collinear neighbour.
constexpr double kLineMinPiecePx = 8.0;
// A pixel's part in the ridge.
constexpr uint8_t kLineNoRidge = 0, kLineFreeRidge = 1, kLineTakenRidge = 2;

// Principal axis (unit) of a 2x2 weighted scatter [sxx sxy; sxy syy].
Eigen::Vector2d LinePrincipalAxis(double sxx, double sxy, double syy) {
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  return {std::cos(angle), std::sin(angle)};
}

constexpr int kLineBlock = 16;

// Whether column x of a row is a local maximum of the squared magnitude m2 across the edge, with
// the rows above and below; the gradient quantized to 45 degrees (tan 22.5 ~ 0.4). All neighbours
// are loaded and then selected, so that a loop over x vectorizes.
inline uint8_t LineRidgeFlag(int x, const int32_t* m2, const int32_t* up, const int32_t* down,
                             const int16_t* gxr, const int16_t* gyr, int32_t threshold2) {
  const int gx = gxr[x], gy = gyr[x];
  const int ax = gx < 0 ? -gx : gx, ay = gy < 0 ? -gy : gy;
  const bool horizontal = 5 * ay <= 2 * ax, vertical = 5 * ax <= 2 * ay, same = (gx ^ gy) >= 0;
  const int32_t l = m2[x - 1], r = m2[x + 1], u = up[x], d = down[x];
  const int32_t ul = up[x - 1], ur = up[x + 1], dl = down[x - 1], dr = down[x + 1];
  const int32_t before = horizontal ? l : (vertical ? u : (same ? ul : ur));
  const int32_t after = horizontal ? r : (vertical ? d : (same ? dr : dl));
  const int32_t m = m2[x];
  // Strictly above one neighbour: of two equal maxima (an edge between pixels) one is kept.
  return static_cast<uint8_t>((m >= threshold2) & (m > before) & (m >= after));
}

// Orientation of a line in [0, pi): the edges of an occluding contour against a textured
// background flip polarity along it, and their pieces still join.
double LineOrientation(const Eigen::Vector2d& dir) {
  const double a = std::atan2(dir.y(), dir.x());
  return a < 0.0 ? a + M_PI : (a >= M_PI ? a - M_PI : a);
}

}  // namespace

LineSegmentDetector::LineSegmentDetector(const LineSegmentOptions& options) : options_(options) {
  min_magnitude_sobel_ = static_cast<float>(options_.min_gradient) * kLineSobelScale;
  cos_tolerance_ = static_cast<float>(std::cos(options_.angle_tolerance_deg * M_PI / 180.0));
}

void LineSegmentDetector::Resize(int width, int height) {
  width_ = width;
  height_ = height;
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  rows_.assign(n, 0);
  smooth_.assign(n, 0);
  gx_.assign(n, 0);
  gy_.assign(n, 0);
  magnitude2_.assign(n, 0);
  ridge_index_.assign(n, 0);
  // Ridge pixels are local maxima along the gradient, so at most about half the pixels; the cap
  // only matters for pathological images (the rest of the image is then ignored).
  const size_t max_ridge = n / 2 + 1;
  ridge_.clear();
  ridge_.reserve(max_ridge);
  ridge_pixel_.clear();
  ridge_pixel_.reserve(max_ridge);
  state_.assign(n, kLineNoRidge);
  row_candidates_.assign(static_cast<size_t>(width), 0);
  // Padded so that eight flags can be read from any column (the tail is never set).
  row_flags_.assign(static_cast<size_t>(width) + 8, 0);
  region_pixel_.clear();
  region_pixel_.reserve(max_ridge);
  seeds_.clear();
  seeds_.reserve(max_ridge);
  region_.clear();
  region_.reserve(max_ridge);
  ordered_.clear();
  ordered_.reserve(max_ridge);
  pieces_.clear();
  pieces_.reserve(max_ridge);
  bucket_count_.assign(kLineSeedBuckets + 1, 0);
  const size_t max_candidates = max_ridge / static_cast<size_t>(kLineMinPiecePx / std::sqrt(2.0)) + 1;
  candidates_.clear();
  candidates_.reserve(max_candidates);
  order_.clear();
  order_.reserve(max_candidates);
  moments_.clear();
  moments_.reserve(max_candidates);
  by_angle_.clear();
  by_angle_.reserve(max_candidates);
}

void LineSegmentDetector::ComputeGradients(const uint8_t* image, int stride) {
  const int w = width_, h = height_;
  const size_t ws = static_cast<size_t>(w);
  // Binomial [1 4 6 4 1] smoothing (sigma 1 px) in both directions: it halves the gradient noise
  // per unit of edge contrast, so weaker edges clear the threshold while noise does not. Plain
  // integer loops that the compiler vectorizes.
  for (int y = 0; y < h; ++y) {
    const uint8_t* r = image + static_cast<ptrdiff_t>(y) * stride;
    uint16_t* o = rows_.data() + static_cast<size_t>(y) * ws;
    for (int x = 2; x + 2 < w; ++x) {
      o[x] = static_cast<uint16_t>(r[x - 2] + 4 * (r[x - 1] + r[x + 1]) + 6 * r[x] + r[x + 2]);
    }
  }
  for (int y = 2; y + 2 < h; ++y) {
    const uint16_t* a = rows_.data() + static_cast<size_t>(y - 2) * ws;
    const uint16_t *b = a + ws, *c = b + ws, *d = c + ws, *e = d + ws;
    uint16_t* o = smooth_.data() + static_cast<size_t>(y) * ws;
    for (int x = 2; x + 2 < w; ++x) {
      o[x] = static_cast<uint16_t>(a[x] + 4 * (b[x] + d[x]) + 6 * c[x] + e[x]);
    }
  }
  for (int y = kLineBorder; y + kLineBorder < h; ++y) {
    const uint16_t* r0 = smooth_.data() + static_cast<size_t>(y - 1) * ws;
    const uint16_t* r1 = r0 + ws;
    const uint16_t* r2 = r1 + ws;
    int16_t* gx = gx_.data() + static_cast<size_t>(y) * ws;
    int16_t* gy = gy_.data() + static_cast<size_t>(y) * ws;
    int32_t* m2 = magnitude2_.data() + static_cast<size_t>(y) * ws;
    for (int x = kLineBorder; x + kLineBorder < w; ++x) {
      const int a = r0[x + 1] - r0[x - 1], b = r1[x + 1] - r1[x - 1], c = r2[x + 1] - r2[x - 1];
      const int d = r2[x - 1] - r0[x - 1], e = r2[x] - r0[x], f = r2[x + 1] - r0[x + 1];
      const int sx = (a + 2 * b + c) >> kLineGradientShift, sy = (d + 2 * e + f) >> kLineGradientShift;
      gx[x] = static_cast<int16_t>(sx);
      gy[x] = static_cast<int16_t>(sy);
      m2[x] = sx * sx + sy * sy;
    }
  }
}

void LineSegmentDetector::SuppressNonMaxima() {
  // Forget the previous image's ridge (cheaper than clearing the whole image).
  for (const int32_t p : ridge_pixel_) state_[static_cast<size_t>(p)] = kLineNoRidge;
  ridge_.clear();
  ridge_pixel_.clear();
  const int w = width_;
  const int32_t threshold2 = static_cast<int32_t>(std::ceil(min_magnitude_sobel_ * min_magnitude_sobel_));
  const size_t cap = ridge_.capacity();
  uint8_t* is_max = row_flags_.data();
  int32_t* candidates = row_candidates_.data();
  for (int y = kLineBorder; y + kLineBorder < height_; ++y) {
    const size_t row = static_cast<size_t>(y) * static_cast<size_t>(w);
    const int32_t* m2 = magnitude2_.data() + row;
    const int32_t* up = m2 - w;
    const int32_t* down = m2 + w;
    const int16_t* gxr = gx_.data() + row;
    const int16_t* gyr = gy_.data() + row;
    // Local maxima across the edge, the gradient quantized to 45 degrees (tan 22.5 ~ 0.4), in
    // blocks of 16 columns: selects, no branches, so the compiler vectorizes them; blocks without
    // a pixel above the threshold (most) are skipped after one vectorized maximum.
    const int end = w - kLineBorder;
    for (int x0 = kLineBorder; x0 < end; x0 += kLineBlock) {
      if (x0 + kLineBlock > end) {
        for (int x = x0; x < end; ++x) is_max[x] = LineRidgeFlag(x, m2, up, down, gxr, gyr, threshold2);
        break;
      }
      int32_t block_max = 0;
      for (int k = 0; k < kLineBlock; ++k) block_max = std::max(block_max, m2[x0 + k]);
      if (block_max < threshold2) {
        std::memset(is_max + x0, 0, kLineBlock);
        continue;
      }
      for (int k = 0; k < kLineBlock; ++k)
        is_max[x0 + k] = LineRidgeFlag(x0 + k, m2, up, down, gxr, gyr, threshold2);
    }
    // Few pixels are maxima: skip eight flags at a time while all are zero.
    int count = 0;
    for (int x0 = kLineBorder; x0 < end; x0 += 8) {
      uint64_t word = 0;
      std::memcpy(&word, is_max + x0, sizeof(word));
      if (word == 0) continue;
      for (int x = x0; x < std::min(x0 + 8, end); ++x) {
        candidates[count] = x;
        count += is_max[x];
      }
    }
    for (int i = 0; i < count; ++i) {
      const int x = candidates[i];
      const int gx = gxr[x], gy = gyr[x];
      const int ax = std::abs(gx), ay = std::abs(gy);
      int dx, dy;
      if (5 * ay <= 2 * ax) {
        dx = 1, dy = 0;
      } else if (5 * ax <= 2 * ay) {
        dx = 0, dy = 1;
      } else {
        dx = (gx ^ gy) >= 0 ? 1 : -1, dy = 1;
      }
      const ptrdiff_t step = static_cast<ptrdiff_t>(dy) * w + dx;
      const int32_t m = m2[x], before = m2[x - step], after = m2[x + step];
      if (ridge_.size() == cap) return;
      // Vertex of the parabola through the three magnitudes.
      const float a = std::sqrt(static_cast<float>(before)), b = std::sqrt(static_cast<float>(m)),
                  c = std::sqrt(static_cast<float>(after));
      const float curvature = a - 2.0f * b + c;
      const float offset = curvature < 0.0f ? std::clamp(0.5f * (a - c) / curvature, -0.5f, 0.5f) : 0.0f;
      RidgePoint r;
      r.x = static_cast<float>(x) + offset * static_cast<float>(dx);
      r.y = static_cast<float>(y) + offset * static_cast<float>(dy);
      r.gx = static_cast<float>(gx);
      r.gy = static_cast<float>(gy);
      r.weight = b;
      state_[row + static_cast<size_t>(x)] = kLineFreeRidge;
      ridge_index_[row + static_cast<size_t>(x)] = static_cast<int32_t>(ridge_.size());
      ridge_.push_back(r);
      ridge_pixel_.push_back(static_cast<int32_t>(row) + x);
    }
  }
}

void LineSegmentDetector::OrderSeeds() {
  // Counting sort on the magnitude, strongest first (LSD's pseudo-ordering).
  std::fill(bucket_count_.begin(), bucket_count_.end(), 0);
  const float scale = static_cast<float>(kLineSeedBuckets - 1) / kLineMaxSobel;
  const auto bucket = [&](const RidgePoint& r) {
    return kLineSeedBuckets - 1 - std::min(kLineSeedBuckets - 1, static_cast<int>(r.weight * scale));
  };
  for (const RidgePoint& r : ridge_) ++bucket_count_[static_cast<size_t>(bucket(r)) + 1];
  for (int b = 0; b < kLineSeedBuckets; ++b)
    bucket_count_[static_cast<size_t>(b) + 1] += bucket_count_[static_cast<size_t>(b)];
  seeds_.resize(ridge_.size());
  for (size_t i = 0; i < ridge_.size(); ++i) {
    seeds_[static_cast<size_t>(bucket_count_[static_cast<size_t>(bucket(ridge_[i]))]++)] =
        static_cast<int32_t>(i);
  }
}

void LineSegmentDetector::GrowRegion(int32_t seed) {
  region_.clear();
  region_pixel_.clear();
  region_.push_back(seed);
  region_pixel_.push_back(ridge_pixel_[static_cast<size_t>(seed)]);
  state_[static_cast<size_t>(region_pixel_[0])] = kLineTakenRidge;
  const RidgePoint& s = ridge_[static_cast<size_t>(seed)];
  // Sum of the members' unit gradients: the region's mean orientation.
  float sx = s.gx / s.weight, sy = s.gy / s.weight;
  const float cos2 = cos_tolerance_ * cos_tolerance_;
  const ptrdiff_t w = width_;
  const ptrdiff_t offsets[8] = {-w - 1, -w, -w + 1, -1, 1, w - 1, w, w + 1};
  // Only per-pixel arrays are read to test a neighbour (they are local in memory, the ridge list
  // is not).
  for (size_t k = 0; k < region_pixel_.size(); ++k) {
    const ptrdiff_t p = region_pixel_[k];
    for (const ptrdiff_t o : offsets) {
      // Ridge pixels are kLineBorder from the border, so their neighbours are inside the image.
      const size_t q = static_cast<size_t>(p + o);
      if (state_[q] != kLineFreeRidge) continue;
      const float gx = gx_[q], gy = gy_[q];
      const float dot = gx * sx + gy * sy;
      const float g2 = gx * gx + gy * gy;
      if (dot <= 0.0f || dot * dot < cos2 * g2 * (sx * sx + sy * sy)) continue;
      state_[q] = kLineTakenRidge;
      region_.push_back(ridge_index_[q]);
      region_pixel_.push_back(static_cast<int32_t>(q));
      const float inv = 1.0f / std::sqrt(g2);
      sx += gx * inv;
      sy += gy * inv;
    }
  }
}

void LineSegmentDetector::FitRegion() {
  double sw = 0.0, mx = 0.0, my = 0.0;
  for (const int32_t i : region_) {
    const RidgePoint& r = ridge_[static_cast<size_t>(i)];
    sw += r.weight;
    mx += r.weight * r.x;
    my += r.weight * r.y;
  }
  mx /= sw;
  my /= sw;
  double sxx = 0.0, sxy = 0.0, syy = 0.0;
  for (const int32_t i : region_) {
    const RidgePoint& r = ridge_[static_cast<size_t>(i)];
    const double dx = r.x - mx, dy = r.y - my;
    sxx += r.weight * dx * dx;
    sxy += r.weight * dx * dy;
    syy += r.weight * dy * dy;
  }
  const Eigen::Vector2d axis = LinePrincipalAxis(sxx, sxy, syy);
  ordered_.clear();
  for (const int32_t i : region_) {
    const RidgePoint& r = ridge_[static_cast<size_t>(i)];
    ordered_.push_back({static_cast<float>((r.x - mx) * axis.x() + (r.y - my) * axis.y()), i});
  }
  std::sort(ordered_.begin(), ordered_.end(), [](const Ordered& a, const Ordered& b) { return a.t < b.t; });
  pieces_.clear();
  pieces_.emplace_back(0, static_cast<int>(ordered_.size()));
  while (!pieces_.empty()) {
    const auto [begin, end] = pieces_.back();
    pieces_.pop_back();
    FitPiece(begin, end);
  }
}

void LineSegmentDetector::Moments::Add(const Moments& o) {
  w += o.w, x += o.x, y += o.y, xx += o.xx, xy += o.xy, yy += o.yy, gx += o.gx, gy += o.gy;
}

void LineSegmentDetector::LineFromMoments(const Moments& m, Eigen::Vector2d* centre, Eigen::Vector2d* dir,
                                          double* sigma) {
  const double mx = m.x / m.w, my = m.y / m.w;
  const double cxx = m.xx / m.w - mx * mx, cxy = m.xy / m.w - mx * my, cyy = m.yy / m.w - my * my;
  *centre = Eigen::Vector2d(mx, my);
  *dir = LinePrincipalAxis(cxx, cxy, cyy);
  // Bright side on +normal, normal = dir turned by +90 degrees in image coordinates.
  if (-dir->y() * m.gx + dir->x() * m.gy < 0.0) *dir = -*dir;
  const double smallest = 0.5 * (cxx + cyy) - std::sqrt(0.25 * (cxx - cyy) * (cxx - cyy) + cxy * cxy);
  *sigma = std::sqrt(std::max(0.0, smallest));
}

void LineSegmentDetector::FitPiece(int begin, int end) {
  const auto point = [&](int k) -> const RidgePoint& {
    return ridge_[static_cast<size_t>(ordered_[static_cast<size_t>(k)].point)];
  };
  Moments m;
  Eigen::Vector2d c, dir, normal;
  double sigma = 0.0, t_min = 0.0, t_max = 0.0;
  float fx = 0.0f, fy = 0.0f;
  for (int round = 0;; ++round) {
    const int n = end - begin;
    if (n < 2) return;
    const RidgePoint& first = point(begin);
    const RidgePoint& last = point(end - 1);
    // Too short even along its ordering axis: no part of it can be kept.
    if (std::hypot(last.x - first.x, last.y - first.y) + 1.0 < kLineMinPiecePx) return;
    // Moments about the first point, which keeps the sums small.
    fx = first.x;
    fy = first.y;
    m = Moments{};
    for (int k = begin; k < end; ++k) {
      const RidgePoint& r = point(k);
      const double dx = r.x - fx, dy = r.y - fy;
      m.w += r.weight;
      m.x += r.weight * dx;
      m.y += r.weight * dy;
      m.xx += r.weight * dx * dx;
      m.xy += r.weight * dx * dy;
      m.yy += r.weight * dy * dy;
      m.gx += r.gx;
      m.gy += r.gy;
    }
    LineFromMoments(m, &c, &dir, &sigma);
    c += Eigen::Vector2d(fx, fy);
    normal = Eigen::Vector2d(-dir.y(), dir.x());
    t_min = INFINITY;
    t_max = -INFINITY;
    double max_residual = 0.0;
    int outliers = 0;
    for (int k = begin; k < end; ++k) {
      const RidgePoint& r = point(k);
      const double dx = r.x - c.x(), dy = r.y - c.y();
      const double t = dx * dir.x() + dy * dir.y(), e = std::abs(dx * normal.x() + dy * normal.y());
      t_min = std::min(t_min, t);
      t_max = std::max(t_max, t);
      max_residual = std::max(max_residual, e);
      outliers += e > options_.max_deviation_px ? 1 : 0;
    }
    if (max_residual <= options_.max_deviation_px || n < 4) break;
    if (round < 2 && 5 * outliers <= n) {
      // A few stray pixels (texture ridges beside the edge, joined at similar orientation):
      // drop them and fit again.
      int kept = begin;
      for (int k = begin; k < end; ++k) {
        const RidgePoint& r = point(k);
        const double e = std::abs((r.x - c.x()) * normal.x() + (r.y - c.y()) * normal.y());
        if (e <= options_.max_deviation_px)
          ordered_[static_cast<size_t>(kept++)] = ordered_[static_cast<size_t>(k)];
      }
      end = kept;
      continue;
    }
    // Bent: split at the point farthest from the chord between the ends (a bend or a corner).
    const double cx = last.x - first.x, cy = last.y - first.y, chord = std::hypot(cx, cy);
    int split = begin + n / 2;
    double farthest = -1.0;
    for (int k = begin + 1; k + 1 < end; ++k) {
      const RidgePoint& r = point(k);
      const double d = std::abs((r.x - first.x) * cy - (r.y - first.y) * cx) / std::max(chord, 1e-9);
      if (d > farthest) {
        farthest = d;
        split = k;
      }
    }
    pieces_.emplace_back(begin, split);
    pieces_.emplace_back(split, end);
    return;
  }
  const int n = end - begin;
  if (t_max - t_min < kLineMinPiecePx || candidates_.size() == candidates_.capacity()) return;
  // Moments about the origin from here on, so that candidates add up.
  m.xx += 2.0 * fx * m.x + fx * fx * m.w;
  m.xy += fx * m.y + fy * m.x + fx * fy * m.w;
  m.yy += 2.0 * fy * m.y + fy * fy * m.w;
  m.x += fx * m.w;
  m.y += fy * m.w;
  m.angle = LineOrientation(dir);
  ImageLineSegment s;
  s.p0 = c + t_min * dir;
  s.p1 = c + t_max * dir;
  s.normal = normal;
  s.length = t_max - t_min;
  s.contrast = m.w / n / kLineSobelScale;
  s.line_sigma_px = sigma;
  s.pixels = n;
  RefineEnds(&s);
  candidates_.push_back(s);
  moments_.push_back(m);
}

bool LineSegmentDetector::TryJoin(int32_t i, int32_t j) {
  ImageLineSegment& a = candidates_[static_cast<size_t>(i)];
  const ImageLineSegment& b = candidates_[static_cast<size_t>(j)];
  const Eigen::Vector2d ta = a.direction();
  // Each one's ends close to the other's line.
  const double tol = options_.max_deviation_px;
  const auto off = [](const ImageLineSegment& s, const Eigen::Vector2d& p) {
    return std::abs(s.normal.dot(p - s.p0));
  };
  if (off(a, b.p0) > tol || off(a, b.p1) > tol || off(b, a.p0) > tol || off(b, a.p1) > tol) return false;
  // In line one after the other: the gap between them (negative: an overlap) short.
  const double b0 = ta.dot(b.p0 - a.p0), b1 = ta.dot(b.p1 - a.p0);
  const double gap = std::max(std::min(b0, b1) - a.length, -std::max(b0, b1));
  const double max_gap =
      std::max(options_.max_gap_px, options_.max_gap_fraction * std::min(a.length, b.length));
  if (gap > max_gap || gap < -options_.max_deviation_px) return false;
  Moments& ma = moments_[static_cast<size_t>(i)];
  Moments& mb = moments_[static_cast<size_t>(j)];
  ma.Add(mb);
  mb.alive = false;
  Eigen::Vector2d c, dir;
  double sigma;
  LineFromMoments(ma, &c, &dir, &sigma);
  double t_min = INFINITY, t_max = -INFINITY;
  for (const Eigen::Vector2d& p : {a.p0, a.p1, b.p0, b.p1}) {
    t_min = std::min(t_min, dir.dot(p - c));
    t_max = std::max(t_max, dir.dot(p - c));
  }
  const double contrast = (a.contrast * a.pixels + b.contrast * b.pixels) / (a.pixels + b.pixels);
  a.p0 = c + t_min * dir;
  a.p1 = c + t_max * dir;
  a.normal = Eigen::Vector2d(-dir.y(), dir.x());
  a.length = t_max - t_min;
  a.contrast = contrast;
  a.line_sigma_px = sigma;
  a.pixels += b.pixels;
  ma.angle = LineOrientation(dir);
  return true;
}

void LineSegmentDetector::JoinCollinear() {
  if (options_.max_gap_px <= 0.0 && options_.max_gap_fraction <= 0.0) return;
  const size_t n = candidates_.size();
  by_angle_.clear();
  for (size_t i = 0; i < n; ++i) by_angle_.push_back(static_cast<int32_t>(i));
  const auto angle_of = [&](int32_t i) { return moments_[static_cast<size_t>(i)].angle; };
  std::sort(by_angle_.begin(), by_angle_.end(),
            [&](int32_t a, int32_t b) { return angle_of(a) < angle_of(b); });
  // Longest first, so that short pieces join the long ones they continue.
  order_.clear();
  for (size_t i = 0; i < n; ++i) order_.push_back(static_cast<int32_t>(i));
  std::sort(order_.begin(), order_.end(), [&](int32_t a, int32_t b) {
    const double la = candidates_[static_cast<size_t>(a)].length,
                 lb = candidates_[static_cast<size_t>(b)].length;
    return la != lb ? la > lb : a < b;
  });
  const double window = options_.angle_tolerance_deg * M_PI / 180.0 * 0.5;
  for (const int32_t i : order_) {
    if (!moments_[static_cast<size_t>(i)].alive) continue;
    for (bool joined = true; joined;) {
      joined = false;
      const double centre = angle_of(i);
      // The orientations within the window, across the wrap at 0 and pi too.
      for (const double shift : {0.0, -M_PI, M_PI}) {
        const double lo = centre + shift - window, hi = centre + shift + window;
        auto it = std::lower_bound(by_angle_.begin(), by_angle_.end(), lo,
                                   [&](int32_t a, double v) { return angle_of(a) < v; });
        for (; it != by_angle_.end() && angle_of(*it) <= hi; ++it) {
          const int32_t j = *it;
          if (j == i || !moments_[static_cast<size_t>(j)].alive) continue;
          if (TryJoin(i, j)) joined = true;
        }
      }
    }
  }
}

float LineSegmentDetector::EdgeResponse(const Eigen::Vector2d& q, const Eigen::Vector2d& normal) const {
  const double lo = kLineBorder, hi_x = width_ - 1 - kLineBorder, hi_y = height_ - 1 - kLineBorder;
  if (!(q.x() >= lo && q.y() >= lo && q.x() <= hi_x && q.y() <= hi_y)) return 0.0f;
  const int x = std::min(static_cast<int>(q.x()), width_ - 2 - kLineBorder);
  const int y = std::min(static_cast<int>(q.y()), height_ - 2 - kLineBorder);
  const float fx = static_cast<float>(q.x() - x), fy = static_cast<float>(q.y() - y);
  const size_t i = static_cast<size_t>(y) * static_cast<size_t>(width_) + static_cast<size_t>(x);
  const size_t w = static_cast<size_t>(width_);
  const auto at = [&](size_t j) {
    return static_cast<float>(normal.x()) * gx_[j] + static_cast<float>(normal.y()) * gy_[j];
  };
  return (1.0f - fy) * ((1.0f - fx) * at(i) + fx * at(i + 1)) +
         fy * ((1.0f - fx) * at(i + w) + fx * at(i + w + 1));
}

void LineSegmentDetector::RefineEnds(ImageLineSegment* s) const {
  constexpr double kStep = 0.25, kReach = 3.0;
  const Eigen::Vector2d t = s->direction();
  for (int e = 0; e < 2; ++e) {
    Eigen::Vector2d& end = e == 0 ? s->p0 : s->p1;
    const Eigen::Vector2d out = e == 0 ? Eigen::Vector2d(-t) : t;
    // The response a few pixels inside this end: the reference its half is taken of (the
    // contrast may change along the edge).
    float reference = 0.0f;
    for (const double inside : {2.0, 3.0, 4.0}) reference += EdgeResponse(end - inside * out, s->normal);
    const float half = reference / 6.0f;
    if (!(half > 0.0f)) continue;
    float previous = EdgeResponse(end, s->normal);
    // Beyond the half point already: walk in instead.
    const double dir = previous >= half ? 1.0 : -1.0;
    for (double k = kStep; k <= kReach + 1e-9; k += kStep) {
      const float r = EdgeResponse(end + dir * k * out, s->normal);
      if ((r < half) == (dir > 0.0)) {
        // Linear crossing between the last two samples.
        const double f = (previous - half) / static_cast<double>(previous - r);
        end += dir * (k - kStep + kStep * std::clamp(f, 0.0, 1.0)) * out;
        break;
      }
      previous = r;
    }
  }
  s->length = (s->p1 - s->p0).norm();
}

bool LineSegmentDetector::Detect(const uint8_t* image, int width, int height, int stride,
                                 std::vector<ImageLineSegment>* segments, Stats* stats) {
  segments->clear();
  segments->reserve(static_cast<size_t>(options_.max_segments));
  if (image == nullptr || width < 2 * kLineBorder + 1 || height < 2 * kLineBorder + 1 || stride < width)
    return false;
  if (width != width_ || height != height_) Resize(width, height);
  ComputeGradients(image, stride);
  SuppressNonMaxima();
  OrderSeeds();
  candidates_.clear();
  moments_.clear();
  int regions = 0;
  const size_t min_region = static_cast<size_t>(kLineMinPiecePx / std::sqrt(2.0));
  for (const int32_t seed : seeds_) {
    if (state_[static_cast<size_t>(ridge_pixel_[static_cast<size_t>(seed)])] != kLineFreeRidge) continue;
    GrowRegion(seed);
    if (region_.size() < min_region) continue;
    ++regions;
    FitRegion();
  }
  JoinCollinear();
  order_.clear();
  for (size_t i = 0; i < candidates_.size(); ++i) {
    if (moments_[i].alive && candidates_[i].length >= options_.min_length_px)
      order_.push_back(static_cast<int32_t>(i));
  }
  const auto longer = [&](int32_t a, int32_t b) {
    const double la = candidates_[static_cast<size_t>(a)].length,
                 lb = candidates_[static_cast<size_t>(b)].length;
    return la != lb ? la > lb : a < b;
  };
  const size_t keep = std::min(order_.size(), static_cast<size_t>(options_.max_segments));
  std::partial_sort(order_.begin(), order_.begin() + static_cast<ptrdiff_t>(keep), order_.end(), longer);
  for (size_t i = 0; i < keep; ++i) segments->push_back(candidates_[static_cast<size_t>(order_[i])]);
  if (stats != nullptr) {
    stats->ridge_pixels = static_cast<int>(ridge_.size());
    stats->regions = regions;
    stats->segments = static_cast<int>(order_.size());
  }
  return true;
}

}  // namespace cairn
