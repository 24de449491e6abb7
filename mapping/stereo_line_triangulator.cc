#include "mapping/stereo_line_triangulator.h"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace cairn {
namespace {

// Blocks along the segment whose median disparities start the robust fit.
constexpr int kStereoLineBlocks = 4;
// Floor of an image line fit's residual sigma: its ridge positions carry subpixel interpolation
// bias that a perfect synthetic edge shows as no scatter at all.
constexpr double kStereoLineMinLineSigmaPx = 0.05;
// An occlusion shadow lies left of the edge: the missing side's normal at least this far towards
// -x (edges within 72 degrees of vertical); checked at this many places along the segment, its
// band at most the near disparity plus this margin wide.
constexpr double kStereoLineShadowMinCos = 0.3;
constexpr int kStereoLineShadowChecks = 5;
constexpr int kStereoLineShadowMarginPx = 3;

}  // namespace

StereoLineTriangulator::StereoLineTriangulator(const StereoLineOptions& options, const StereoCamera& camera)
    : options_(options), camera_(camera) {
  disparity_sigma_ = std::sqrt(2.0) * options_.pixel_error_px;
  const double diagonal = std::hypot(camera_.intrinsics.width, camera_.intrinsics.height);
  const size_t per_side = static_cast<size_t>(options_.side_rows) *
                          (static_cast<size_t>(diagonal / options_.sample_spacing_px) + 2);
  bright_.samples.reserve(per_side);
  dark_.samples.reserve(per_side);
  scratch_.reserve(per_side);
}

void StereoLineTriangulator::SampleSide(const ImageLineSegment& seg, double sign,
                                        const StereoMatcherOutput& disparity, SideSamples* side) const {
  side->samples.clear();
  side->requested = 0;
  const Eigen::Vector2d t = seg.direction(), n = seg.normal * sign;
  const int along = std::max(2, static_cast<int>(seg.length / options_.sample_spacing_px) + 1);
  const double half = 0.5 * seg.length;
  const int w = disparity.width, h = disparity.height;
  for (int row = 0; row < options_.side_rows; ++row) {
    const double r = options_.side_offset_px + row * options_.side_row_spacing_px;
    for (int k = 0; k < along; ++k) {
      const double s = seg.length * k / (along - 1);
      const Eigen::Vector2d q = seg.p0 + s * t + r * n;
      const int x = static_cast<int>(std::lround(q.x())), y = static_cast<int>(std::lround(q.y()));
      if (x < 0 || y < 0 || x >= w || y >= h) continue;
      ++side->requested;
      const int16_t d16 =
          disparity.disparity[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)];
      if (d16 == kInvalidDisparity || d16 <= 0) continue;
      // The sample's own pixel, in the segment's frame (exact, not the rounded request).
      const Eigen::Vector2d rel = Eigen::Vector2d(x, y) - seg.p0;
      Sample smp;
      smp.nominal_s = static_cast<float>(s);
      smp.s = static_cast<float>(rel.dot(t) - half);
      smp.r = static_cast<float>(std::abs(rel.dot(n)));
      smp.d = static_cast<float>(d16) / static_cast<float>(kDisparityScale);
      side->samples.push_back(smp);
    }
  }
}

StereoLineTriangulator::SideFit StereoLineTriangulator::FitSide(SideSamples& side, double half_length) {
  SideFit fit;
  std::vector<Sample>& samples = side.samples;
  fit.samples = static_cast<int>(samples.size());
  if (fit.samples < options_.min_support || fit.samples < options_.min_valid_fraction * side.requested)
    return fit;
  // Start: a line through the median disparities of blocks along the segment, robust to a
  // minority of samples from another surface in each block.
  double bs[kStereoLineBlocks], bd[kStereoLineBlocks];
  int blocks = 0;
  const double length = 2.0 * half_length;
  for (int b = 0; b < kStereoLineBlocks; ++b) {
    scratch_.clear();
    double sum_s = 0.0;
    for (const Sample& smp : samples) {
      const int block =
          std::min(kStereoLineBlocks - 1, static_cast<int>(smp.nominal_s / length * kStereoLineBlocks));
      if (block != b) continue;
      scratch_.push_back(smp.d);
      sum_s += smp.s;
    }
    if (scratch_.size() < 3) continue;
    const auto mid = scratch_.begin() + static_cast<ptrdiff_t>(scratch_.size() / 2);
    std::nth_element(scratch_.begin(), mid, scratch_.end());
    bs[blocks] = sum_s / static_cast<double>(scratch_.size());
    bd[blocks] = *mid;
    ++blocks;
  }
  if (blocks == 0) return fit;
  Eigen::Vector3d abc = Eigen::Vector3d::Zero();
  if (blocks == 1) {
    abc[0] = bd[0];
  } else {
    double ms = 0.0, md = 0.0;
    for (int b = 0; b < blocks; ++b) ms += bs[b], md += bd[b];
    ms /= blocks;
    md /= blocks;
    double sss = 0.0, ssd = 0.0;
    for (int b = 0; b < blocks; ++b) sss += (bs[b] - ms) * (bs[b] - ms), ssd += (bs[b] - ms) * (bd[b] - md);
    abc[1] = sss > 1e-9 ? ssd / sss : 0.0;
    abc[0] = md - abc[1] * ms;
  }
  // Samples closer than the correlation length carry one error between them: weigh the data as
  // that many times fewer samples (along the segment and across its rows).
  const double corr = options_.disparity_correlation_px;
  const double along_factor = std::max(1.0, corr / options_.sample_spacing_px);
  const double across_factor =
      std::max(1.0, std::min(static_cast<double>(options_.side_rows),
                             options_.side_rows > 1 ? corr / options_.side_row_spacing_px : 1.0));
  const double sigma2 = disparity_sigma_ * disparity_sigma_;
  const double data_weight = 1.0 / (sigma2 * along_factor * across_factor);
  const double prior = 1.0 / (options_.disparity_slope_prior * options_.disparity_slope_prior);
  const double band = options_.inlier_sigmas * disparity_sigma_;
  Eigen::Matrix3d A;
  double chi2 = 0.0;
  int inliers = 0;
  // Inliers of the current model, refitted; three rounds settle.
  for (int round = 0; round < 3; ++round) {
    A.setZero();
    Eigen::Vector3d rhs = Eigen::Vector3d::Zero();
    chi2 = 0.0;
    inliers = 0;
    for (const Sample& smp : samples) {
      const double e = smp.d - (abc[0] + abc[1] * smp.s + abc[2] * smp.r);
      if (std::abs(e) > band) continue;
      const Eigen::Vector3d x(1.0, smp.s, smp.r);
      A.selfadjointView<Eigen::Upper>().rankUpdate(x, data_weight);
      rhs += data_weight * smp.d * x;
      ++inliers;
    }
    if (inliers < 3) return fit;
    A = A.selfadjointView<Eigen::Upper>();
    A(2, 2) += prior;
    abc = A.ldlt().solve(rhs);
  }
  fit.s_lo = INFINITY;
  fit.s_hi = -INFINITY;
  inliers = 0;
  for (const Sample& smp : samples) {
    const double e = smp.d - (abc[0] + abc[1] * smp.s + abc[2] * smp.r);
    if (std::abs(e) > band) continue;
    chi2 += e * e / sigma2;
    ++inliers;
    fit.s_lo = std::min(fit.s_lo, static_cast<double>(smp.nominal_s));
    fit.s_hi = std::max(fit.s_hi, static_cast<double>(smp.nominal_s));
  }
  fit.inliers = inliers;
  if (inliers < options_.min_support || inliers < options_.min_inlier_fraction * fit.samples) return fit;
  // Where the disparities scatter more than the model says (SGM near edges), the fit's covariance
  // grows by the reduced chi-square.
  const double inflation = std::max(1.0, chi2 / std::max(1, inliers - 3));
  const Eigen::Matrix3d cov = A.inverse() * inflation;
  fit.ab = abc.head<2>();
  fit.cov = cov.topLeftCorner<2, 2>();
  fit.valid = true;
  return fit;
}

double StereoLineTriangulator::NearerFraction(const std::vector<Sample>& samples, const SideFit& fit) const {
  if (samples.empty()) return 0.0;
  const double band = options_.inlier_sigmas * disparity_sigma_;
  int nearer = 0;
  for (const Sample& smp : samples) nearer += smp.d - (fit.ab[0] + fit.ab[1] * smp.s) > band ? 1 : 0;
  return static_cast<double>(nearer) / static_cast<double>(samples.size());
}

bool StereoLineTriangulator::LooksLikeOcclusionShadow(const ImageLineSegment& seg, double missing_sign,
                                                      const SideFit& near,
                                                      const StereoMatcherOutput& disparity) const {
  // Background just left of a nearer surface's left edge is seen by the left camera only (the
  // right one, shifted right, sees the surface in front of it): a band of no disparity, as wide
  // as the two disparities differ, then the background's smaller disparity. Nothing else leaves a
  // side without disparity but texture-less surfaces, which may be nearer.
  const Eigen::Vector2d missing = missing_sign * seg.normal;
  if (missing.x() > -kStereoLineShadowMinCos) return false;
  const Eigen::Vector2d t = seg.direction();
  const double half = 0.5 * seg.length;
  const int w = disparity.width, h = disparity.height;
  int shadows = 0;
  for (int k = 0; k < kStereoLineShadowChecks; ++k) {
    const double s = near.s_lo + (near.s_hi - near.s_lo) * (k + 0.5) / kStereoLineShadowChecks;
    const Eigen::Vector2d q = seg.p0 + s * t;
    const double d_near = near.ab.dot(Eigen::Vector2d(1.0, s - half));
    const int y = static_cast<int>(std::lround(q.y())), x0 = static_cast<int>(std::lround(q.x()));
    if (y < 0 || y >= h) continue;
    // Leftwards along the row, past SGM's spread of the near disparity over the band.
    const int reach = static_cast<int>(std::ceil(d_near)) + kStereoLineShadowMarginPx;
    for (int x = x0 - 1; x >= std::max(0, x0 - reach); --x) {
      const int16_t d16 =
          disparity.disparity[static_cast<size_t>(y) * static_cast<size_t>(w) + static_cast<size_t>(x)];
      if (d16 == kInvalidDisparity) continue;
      if (static_cast<double>(d16) / kDisparityScale < d_near - 1.0) {
        ++shadows;
        break;
      }
    }
  }
  return 2 * shadows > kStereoLineShadowChecks;
}

bool StereoLineTriangulator::Triangulate(std::span<const ImageLineSegment> segments,
                                         const StereoMatcherOutput& disparity,
                                         std::vector<StereoLineSegment>* out, Stats* stats) {
  out->clear();
  out->reserve(segments.size());
  Stats local;
  Stats& st = stats != nullptr ? *stats : local;
  st = Stats{};
  const PinholeRadTan& k = camera_.intrinsics;
  if (disparity.width != k.width || disparity.height != k.height ||
      disparity.disparity.size() != static_cast<size_t>(k.width) * static_cast<size_t>(k.height)) {
    return false;
  }
  const double b = camera_.baseline;
  for (const ImageLineSegment& seg : segments) {
    if (!(seg.length > 0.0)) continue;
    const double half = 0.5 * seg.length;
    SampleSide(seg, 1.0, disparity, &bright_);
    SampleSide(seg, -1.0, disparity, &dark_);
    const SideFit bright = FitSide(bright_, half);
    const SideFit dark = FitSide(dark_, half);
    SideFit use;
    LineDepthSide side = LineDepthSide::kBoth;
    if (bright.valid && dark.valid) {
      // Do both sides' edge disparities agree at the ends of the segment?
      bool agree = true;
      for (const double s : {-half, half}) {
        const Eigen::Vector2d x(1.0, s);
        const double diff = (bright.ab - dark.ab).dot(x);
        const double var = x.dot((bright.cov + dark.cov) * x);
        if (std::abs(diff) > options_.inlier_sigmas * std::sqrt(var)) agree = false;
      }
      if (agree) {
        // Information-weighted fusion of the two fits (their samples are disjoint).
        const Eigen::Matrix2d ib = bright.cov.inverse(), id = dark.cov.inverse();
        use.cov = (ib + id).inverse();
        use.ab = use.cov * (ib * bright.ab + id * dark.ab);
        use.s_lo = std::min(bright.s_lo, dark.s_lo);
        use.s_hi = std::max(bright.s_hi, dark.s_hi);
        use.inliers = bright.inliers + dark.inliers;
        use.valid = true;
      } else {
        // An occluding edge is the nearer surface's; the other side is background.
        const bool bright_nearer = bright.ab[0] > dark.ab[0];
        use = bright_nearer ? bright : dark;
        side = bright_nearer ? LineDepthSide::kBright : LineDepthSide::kDark;
      }
    } else if (bright.valid || dark.valid) {
      use = bright.valid ? bright : dark;
      side = bright.valid ? LineDepthSide::kBright : LineDepthSide::kDark;
      const SideSamples& other = bright.valid ? dark_ : bright_;
      const bool other_has_data =
          other.requested > 0 && other.samples.size() >= options_.min_valid_fraction * other.requested;
      // The other side scattered: if many of its samples are nearer than this one, the edge may
      // be theirs and this side the background. The other side without data: it may be a nearer
      // surface without texture just as well as background hidden from the right camera; only the
      // latter's geometry makes this side the edge's.
      const bool ambiguous = other_has_data
                                 ? NearerFraction(other.samples, use) > 1.0 - options_.min_inlier_fraction
                                 : !LooksLikeOcclusionShadow(seg, bright.valid ? -1.0 : 1.0, use, disparity);
      if (ambiguous) {
        ++st.ambiguous;
        continue;
      }
    } else {
      ++st.no_depth;
      continue;
    }
    if (use.inliers < options_.min_support || !(use.s_hi > use.s_lo)) {
      ++st.no_depth;
      continue;
    }

    // Ends: image position, disparity and the covariance of (u, v, d) at each.
    const Eigen::Vector2d t = seg.direction(), n = seg.normal;
    const double s_end[2] = {use.s_lo, use.s_hi};
    const double line_sigma = std::max(seg.line_sigma_px, kStereoLineMinLineSigmaPx);
    const double pixels = std::max(2, seg.pixels);
    const double along2 = options_.endpoint_sigma_px * options_.endpoint_sigma_px;
    Eigen::Vector3d p[2];
    Eigen::Matrix3d J[2];
    Eigen::Vector2d x[2];
    bool ok = true;
    for (int e = 0; e < 2; ++e) {
      const Eigen::Vector2d uv = seg.p0 + s_end[e] * t;
      x[e] = Eigen::Vector2d(1.0, s_end[e] - half);
      const double d = use.ab.dot(x[e]);
      if (!(d >= options_.min_disparity_px)) {
        ok = false;
        break;
      }
      const double z = k.fx * b / d;
      p[e] = Eigen::Vector3d((uv.x() - k.cx) * z / k.fx, (uv.y() - k.cy) * z / k.fy, z);
      // d(x, y, z) / d(u, v, d)
      // clang-format off
      J[e] << z / k.fx, 0.0,      -p[e].x() / d,
              0.0,      z / k.fy, -p[e].y() / d,
              0.0,      0.0,      -z / d;
      // clang-format on
    }
    if (!ok) {
      ++st.too_far;
      continue;
    }
    // Along the line an end's error moves it along the image line and, with the fit's slope,
    // along the disparity: (t, b) ds. Across it the image line fit's error, whose offset and
    // angle the two ends share; the disparity fit's error, shared through (a, b).
    const Eigen::Vector3d w_along(t.x(), t.y(), use.ab[1]);
    const Eigen::Vector3d w_perp(n.x(), n.y(), 0.0);
    const double angle_term = 12.0 / (seg.length * seg.length);
    Eigen::Matrix3d S[2], S01;
    for (int e = 0; e < 2; ++e) {
      const double off = s_end[e] - half;
      const double perp2 = line_sigma * line_sigma / pixels * (1.0 + angle_term * off * off);
      S[e] = along2 * w_along * w_along.transpose() + perp2 * w_perp * w_perp.transpose();
      S[e](2, 2) += x[e].dot(use.cov * x[e]);
    }
    const double perp01 =
        line_sigma * line_sigma / pixels * (1.0 + angle_term * (s_end[0] - half) * (s_end[1] - half));
    S01 = perp01 * w_perp * w_perp.transpose();
    S01(2, 2) += x[0].dot(use.cov * x[1]);
    StereoLineSegment r;
    r.p0 = p[0];
    r.p1 = p[1];
    r.cov0 = J[0] * S[0] * J[0].transpose();
    r.cov1 = J[1] * S[1] * J[1].transpose();
    r.cov01 = J[0] * S01 * J[1].transpose();
    if (std::sqrt(r.cov0(2, 2)) > options_.max_depth_sigma ||
        std::sqrt(r.cov1(2, 2)) > options_.max_depth_sigma) {
      ++st.too_far;
      continue;
    }
    r.segment = seg;
    r.image_p0 = seg.p0 + s_end[0] * t;
    r.image_p1 = seg.p0 + s_end[1] * t;
    r.support = use.inliers;
    r.side = side;
    out->push_back(r);
    ++st.triangulated;
  }
  return true;
}

}  // namespace cairn
