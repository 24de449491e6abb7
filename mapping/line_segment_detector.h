#pragma once
// Straight line segments in a rectified 8-bit gray image (paper 000: segments longer than a minimum
// length become landmarks). Sobel gradients of the image smoothed by a binomial filter, thinned to their
// ridge by non-maximum suppression with a subpixel offset along the gradient; the ridge pixels are grown,
// strongest first, into regions whose gradient orientation stays within a tolerance of the region's mean
// (line-support regions); each region is fitted by weighted least squares and split where it bends, its ends
// placed where the edge response along the line falls to half (a corner's subpixel position), and
// the pieces longer than the minimum become segments, longest first. All buffers are sized on the
// first image of a size and reused: later images of that size do not allocate.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"

namespace cairn {

struct LineSegmentOptions {
  double min_length_px = 60.0;  // paper 000 kept segments longer than 60 px
  int64_t max_segments = 200;   // the longest ones are kept
  // Gradient magnitude (central difference of the smoothed image) a ridge pixel needs, well above
  // the gradient noise: the rendered cameras' read plus shot noise of 4-5 DN at mid gray gives
  // about 0.7 DN/px. A sharp edge of contrast C peaks at about C / 3 per px. Lower values let
  // weaker edges and texture through, at a cost in time.
  double min_gradient = 5.0;
  double angle_tolerance_deg = 22.5;  // of a pixel's gradient from its region's mean orientation
  // A region is split at its farthest pixel while one lies farther than this from the chord.
  double max_deviation_px = 1.0;
  // Two segments on one line are joined across a gap of at most this, or of this fraction of the
  // shorter one: noise breaks ridges, and an occluding contour's contrast against textured ground
  // vanishes where their brightness matches.
  double max_gap_px = 8.0;
  double max_gap_fraction = 0.25;

  void Visit(OptionsVisitor& v) {
    v.Number("min_length_px", min_length_px, 3.0, 10000.0, "px");
    v.Integer("max_segments", max_segments, 1, 100000, "segments");
    v.Number("min_gradient", min_gradient, 0.5, 255.0, "DN/px");
    v.Number("angle_tolerance_deg", angle_tolerance_deg, 1.0, 60.0, "deg");
    v.Number("max_deviation_px", max_deviation_px, 0.1, 10.0, "px");
    v.Number("max_gap_px", max_gap_px, 0.0, 50.0, "px");
    v.Number("max_gap_fraction", max_gap_fraction, 0.0, 1.0, "");
  }
};

// One detected segment in pixel coordinates (pixel centres at integers). The gradient points from
// dark to bright across the edge: `normal` is its mean direction, so the bright side is +normal.
struct ImageLineSegment {
  Eigen::Vector2d p0 = Eigen::Vector2d::Zero();
  Eigen::Vector2d p1 = Eigen::Vector2d::Zero();
  Eigen::Vector2d normal = Eigen::Vector2d::UnitX();  // unit, perpendicular to p1 - p0
  double length = 0.0;                                // px
  double contrast = 0.0;                              // mean gradient magnitude along it, DN/px
  double line_sigma_px = 0.0;                         // RMS distance of its ridge pixels from the fitted line
  int pixels = 0;                                     // ridge pixels fitted

  Eigen::Vector2d direction() const { return (p1 - p0) / length; }
};

class LineSegmentDetector {
 public:
  explicit LineSegmentDetector(const LineSegmentOptions& options);

  struct Stats {
    int ridge_pixels = 0;  // after non-maximum suppression
    int regions = 0;       // line-support regions long enough to fit
    int segments = 0;      // before keeping the longest max_segments
  };
  // Segments of the image (`stride` bytes between rows), longest first, into `segments` (cleared,
  // and given room for max_segments: a vector reused across images allocates only once). False when the image
  // is smaller than 7 x 7 or `image` is null.
  bool Detect(const uint8_t* image, int width, int height, int stride,
              std::vector<ImageLineSegment>* segments, Stats* stats = nullptr);

  const LineSegmentOptions& options() const { return options_; }

 private:
  struct RidgePoint {
    float x = 0.0f, y = 0.0f;    // subpixel position
    float gx = 0.0f, gy = 0.0f;  // gradient (Sobel units)
    float weight = 0.0f;         // gradient magnitude
  };
  struct Ordered {
    float t = 0.0f;  // position along the region's line
    int32_t point = 0;
  };

  void Resize(int width, int height);
  void ComputeGradients(const uint8_t* image, int stride);
  void SuppressNonMaxima();
  void OrderSeeds();
  // Grows a region from ridge pixel `seed`; its points go to region_.
  void GrowRegion(int32_t seed);
  // Fits and splits region_ into segments appended to candidates_.
  void FitRegion();
  // Least-squares line of ordered_[begin, end): appends a segment when long enough, or splits.
  void FitPiece(int begin, int end);
  void JoinCollinear();
  // Moves both ends to where the edge response along the line falls to half its value inside.
  void RefineEnds(ImageLineSegment* s) const;
  // Gradient across the edge (Sobel units) at a subpixel position, bilinear; 0 outside.
  float EdgeResponse(const Eigen::Vector2d& q, const Eigen::Vector2d& normal) const;

  LineSegmentOptions options_;
  int width_ = 0, height_ = 0;
  float min_magnitude_sobel_ = 0.0f;
  float cos_tolerance_ = 0.0f;

  std::vector<uint16_t> rows_, smooth_;  // the image smoothed along rows, then along columns
  std::vector<int16_t> gx_, gy_;
  std::vector<int32_t> magnitude2_;      // squared Sobel magnitude
  std::vector<uint8_t> state_;           // per pixel: not ridge, ridge not in a region yet, in one
  std::vector<int32_t> ridge_index_;     // per ridge pixel: its index into ridge_
  std::vector<int32_t> row_candidates_;  // one row's ridge columns
  std::vector<uint8_t> row_flags_;
  std::vector<RidgePoint> ridge_;
  std::vector<int32_t> ridge_pixel_;  // pixel of each ridge point
  std::vector<int32_t> seeds_;        // ridge points, strongest first
  std::vector<int32_t> bucket_count_;
  std::vector<int32_t> region_;        // ridge points
  std::vector<int32_t> region_pixel_;  // their pixels
  std::vector<Ordered> ordered_;
  std::vector<std::pair<int, int>> pieces_;  // work stack of FitRegion
  // Weighted moments of a candidate's ridge points, so that joined candidates are refitted exactly.
  struct Moments {
    double w = 0.0, x = 0.0, y = 0.0, xx = 0.0, xy = 0.0, yy = 0.0;
    double gx = 0.0, gy = 0.0;  // summed gradient: which side is bright
    double angle = 0.0;         // of the candidate's line, in [0, pi)
    bool alive = true;
    void Add(const Moments& o);
  };
  // The weighted least-squares line of `m`: centroid, direction (bright side on the left turn of
  // it) and the weighted RMS distance of the points from it.
  static void LineFromMoments(const Moments& m, Eigen::Vector2d* centre, Eigen::Vector2d* dir, double* sigma);
  // Joins candidate j into i when they continue one line across a short gap.
  bool TryJoin(int32_t i, int32_t j);

  std::vector<ImageLineSegment> candidates_;
  std::vector<Moments> moments_;
  std::vector<int32_t> order_;
  std::vector<int32_t> by_angle_;
};

}  // namespace cairn
