#pragma once
// 3-D line segments from image line segments and the keyframe's disparity (paper 000's line
// landmarks from stereo instead of monocular initialization). The disparity is sampled in rows
// parallel to the segment on both sides of its edge: a fold or a painted line has the same depth on
// both, an occluding edge belongs to the nearer side, and the farther side there is background
// (or, next to the edge, a mix of both that SGM smears across it). Each side's samples are fitted
// robustly with d = a + b s + c r (s along the segment, r the distance from the edge; disparity is
// affine along an image line for a 3-D line, and c is the surface's slope across it, held near
// zero by a prior); the edge's disparity is that fit at r = 0. One side without disparity is
// accepted only where it is the band of background the right camera cannot see (left of a nearer
// surface), since a nearer surface without texture leaves the same gap. The segment is clipped to
// the samples that support the fit and its ends are triangulated in the rectified left camera's
// frame, each with the covariance propagated from the fit, the image line fit and the ends'
// position along the line (rectified rigs: no disparity offset).

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "mapping/depth_image.h"
#include "mapping/line_segment_detector.h"
#include "stereo/stereo_matcher_interface.h"

namespace cairn {

struct StereoLineOptions {
  // Image coordinate sigma of the stereo error model (eq. 5.2): a disparity sample's sigma is
  // sqrt(2) times this (both images' columns).
  double pixel_error_px = 0.5;
  // Where a segment's ends lie along it (detection and clipping), one sigma.
  double endpoint_sigma_px = 1.0;
  double sample_spacing_px = 2.0;  // along the segment
  double side_offset_px = 2.0;     // first sample row from the edge, each side
  int64_t side_rows = 3;           // sample rows per side
  double side_row_spacing_px = 1.5;
  // Prior sigma of the disparity's slope across the edge (a surface at 1.5 m turned 60 degrees
  // from the image plane has about 0.05 px/px at the rover's 0.09 m baseline).
  double disparity_slope_prior = 0.1;
  // SGM's disparity errors are correlated over about its census window: samples closer than this
  // count as one in the fit's covariance. 0: independent samples.
  double disparity_correlation_px = 5.0;
  double inlier_sigmas = 3.0;        // of a disparity sample, from its side's fit
  double min_inlier_fraction = 0.7;  // of a side's valid samples, else the side is mixed
  // Of a side's samples inside the image, those with a disparity; fewer: the side is a shadow of
  // occlusion (seen by the left camera only), whatever SGM spread into it from the edge.
  double min_valid_fraction = 0.5;
  int64_t min_support = 12;  // inlier samples of the side(s) used
  double min_disparity_px = 1.0;
  double max_depth_sigma = 0.15;  // m, each end's depth sigma; farther segments are dropped

  void Visit(OptionsVisitor& v) {
    v.Number("pixel_error_px", pixel_error_px, 0.01, 10.0, "px");
    v.Number("endpoint_sigma_px", endpoint_sigma_px, 0.01, 50.0, "px");
    v.Number("sample_spacing_px", sample_spacing_px, 0.5, 50.0, "px");
    v.Number("side_offset_px", side_offset_px, 0.5, 20.0, "px");
    v.Integer("side_rows", side_rows, 1, 8, "rows");
    v.Number("side_row_spacing_px", side_row_spacing_px, 0.5, 20.0, "px");
    v.Number("disparity_slope_prior", disparity_slope_prior, 0.001, 10.0, "px/px");
    v.Number("disparity_correlation_px", disparity_correlation_px, 0.0, 50.0, "px");
    v.Number("inlier_sigmas", inlier_sigmas, 1.0, 20.0, "");
    v.Number("min_inlier_fraction", min_inlier_fraction, 0.3, 1.0, "");
    v.Number("min_valid_fraction", min_valid_fraction, 0.0, 1.0, "");
    v.Integer("min_support", min_support, 3, 100000, "samples");
    v.Number("min_disparity_px", min_disparity_px, 0.1, 1000.0, "px");
    v.Number("max_depth_sigma", max_depth_sigma, 0.001, 100.0, "m");
  }
};

// Which side of the edge gave the depth: both (a fold or a marking), or the bright (+normal) or
// the dark side alone (an occluding edge, the other side farther).
enum class LineDepthSide : uint8_t { kBoth, kBright, kDark };

struct StereoLineSegment {
  Eigen::Vector3d p0 = Eigen::Vector3d::Zero();  // left camera frame, m
  Eigen::Vector3d p1 = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov0 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov1 = Eigen::Matrix3d::Identity();
  Eigen::Matrix3d cov01 = Eigen::Matrix3d::Zero();     // E[(p0 error)(p1 error)^T]: the ends share one fit
  ImageLineSegment segment;                            // as detected
  Eigen::Vector2d image_p0 = Eigen::Vector2d::Zero();  // the supported part of it, px
  Eigen::Vector2d image_p1 = Eigen::Vector2d::Zero();
  int support = 0;  // inlier disparity samples
  LineDepthSide side = LineDepthSide::kBoth;
};

class StereoLineTriangulator {
 public:
  StereoLineTriangulator(const StereoLineOptions& options, const StereoCamera& camera);

  struct Stats {
    int triangulated = 0;
    int no_depth = 0;  // neither side had a consistent, supported disparity
    // The only consistent side had nearer, inconsistent samples beyond the edge, or none there
    // that an occlusion explains (a texture-less surface there may be the nearer one).
    int ambiguous = 0;
    int too_far = 0;  // an end's depth sigma above max_depth_sigma, or disparity below the minimum
  };
  // Segments of the left image of the pair whose disparity is `disparity` (same size as the
  // camera), into `out` (cleared; its capacity is reused, so it allocates only for more segments
  // than ever before). False when the sizes differ.
  bool Triangulate(std::span<const ImageLineSegment> segments, const StereoMatcherOutput& disparity,
                   std::vector<StereoLineSegment>* out, Stats* stats = nullptr);

  const StereoLineOptions& options() const { return options_; }

 private:
  struct Sample {
    float nominal_s = 0.0f;  // where it was taken along the segment
    float s = 0.0f;          // its pixel's position along the segment (centred)
    float r = 0.0f;          // its pixel's distance from the edge
    float d = 0.0f;          // disparity, px
  };
  // One side's fit of the edge's disparity d(s) = a + b s at r = 0.
  struct SideFit {
    bool valid = false;
    Eigen::Vector2d ab = Eigen::Vector2d::Zero();
    Eigen::Matrix2d cov = Eigen::Matrix2d::Zero();  // of ab
    double s_lo = 0.0, s_hi = 0.0;                  // nominal extent of the inliers
    int inliers = 0;
    int samples = 0;
  };
  // Samples of one side; `requested` counts those inside the image, valid or not.
  struct SideSamples {
    std::vector<Sample> samples;
    int requested = 0;
  };

  void SampleSide(const ImageLineSegment& seg, double sign, const StereoMatcherOutput& disparity,
                  SideSamples* side) const;
  SideFit FitSide(SideSamples& side, double half_length);
  // Fraction of `samples` nearer than `fit` by more than the inlier band.
  double NearerFraction(const std::vector<Sample>& samples, const SideFit& fit) const;
  // Whether the side of `seg` without disparity (missing_sign * normal) is the band of background
  // the right camera cannot see beside the surface `near` fits.
  bool LooksLikeOcclusionShadow(const ImageLineSegment& seg, double missing_sign, const SideFit& near,
                                const StereoMatcherOutput& disparity) const;

  StereoLineOptions options_;
  StereoCamera camera_;
  double disparity_sigma_ = 0.0;
  SideSamples bright_, dark_;
  std::vector<float> scratch_;
};

}  // namespace cairn
