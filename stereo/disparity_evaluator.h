#pragma once
// Scores a disparity map against ground truth the way the Middlebury and KITTI benchmarks do:
// a pixel with ground truth is bad when its estimate is missing or off by more than the threshold
// (KITTI 2012: bad3; KITTI 2015's D1: more than 3 px and more than 5 % of the true disparity).
// KITTI also scores after filling the estimate's holes from the background (InterpolateBackground).

#include <string>

#include "common/status.h"
#include "stereo/pfm_io.h"

namespace cairn {

enum class DisparityMetric { kBad05, kBad1, kBad2, kBad3, kBad4, kD1 };

Expected<DisparityMetric> ParseDisparityMetric(const std::string& name);
const char* DisparityMetricName(DisparityMetric metric);

struct DisparityScore {
  double bad_nonocc = 0.0;  // fraction of scored non-occluded pixels that are bad
  double bad_all = 0.0;     // fraction of all pixels with ground truth that are bad
  double density = 0.0;     // fraction of image pixels with an estimate
  // Fraction of the scored non-occluded pixels with an estimate that are bad: how often a depth
  // that is given is wrong (a phantom obstacle in a map), which counting holes as bad hides.
  double bad_estimated = 0.0;
  long scored_nonocc = 0;
  long scored_all = 0;
  long estimated_nonocc = 0;  // scored non-occluded pixels with an estimate
  bool mask_derived = false;  // non-occluded mask computed from the ground truth itself
};

// Ground truth: PFM (inf or NaN = unknown) or PNG (0 = unknown; value / scale). scale <= 0
// picks 256 for 16-bit PNG (KITTI) and 1 for 8-bit PNG.
Expected<FloatImage> LoadGroundTruth(const std::string& path, double scale);

// Non-occluded mask: 255 where the pixel is visible in both views. `mask` may be empty: then a
// left pixel counts as occluded when its ground truth lands outside the right image or behind a
// nearer ground-truth pixel there.
class DisparityEvaluator {
 public:
  static Expected<DisparityScore> Score(const FloatImage& estimate, const FloatImage& truth,
                                        const FloatImage& mask, DisparityMetric metric);
  static FloatImage DeriveNonOccludedMask(const FloatImage& truth);
  // KITTI's way of scoring a sparse estimate as if dense: in each row, a run of missing pixels
  // between two estimates takes the smaller (farther) of the two and the ends of the row take its
  // nearest estimate; rows above the first row with an estimate copy it, rows below the last copy
  // that one. Rows without any estimate between those stay missing.
  static FloatImage InterpolateBackground(const FloatImage& estimate);
};

// Reads a Middlebury mask PNG (255 non-occluded, 128 occluded, 0 unknown) into a FloatImage.
Expected<FloatImage> LoadMask(const std::string& path);

}  // namespace cairn
