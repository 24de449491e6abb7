#pragma once
// Whether a submap is worth matching (thesis 6.1.1): enough points and obstacle points, and
// keypoints spread off a line in the xy plane. Keypoints along one line (a straight wall, a row of
// stones) or in one spot (a single stone) cannot fix the yaw or the position along the line.

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "mapping/submap.h"

namespace cairn {

struct SuitabilityOptions {
  int64_t min_points = 1000;
  int64_t min_obstacle_points = 100;
  int64_t min_off_line_keypoints = 10;  // keypoints farther than off_line_distance from the line
  double off_line_distance = 0.5;       // m, in xy
  int64_t line_samples = 256;           // RANSAC lines tried (every pair when there are fewer)
  uint32_t seed = 1;                    // of the RANSAC samples: the same input gives the same answer

  void Visit(OptionsVisitor& v) {
    v.Integer("min_points", min_points, 0, 100000000, "points");
    v.Integer("min_obstacle_points", min_obstacle_points, 0, 100000000, "points");
    v.Integer("min_off_line_keypoints", min_off_line_keypoints, 0, 1000000, "keypoints");
    v.Number("off_line_distance", off_line_distance, 0.0, 100.0, "m");
    v.Integer("line_samples", line_samples, 1, 1000000, "lines");
  }
};

enum class SuitabilityReason {
  kSuitable,
  kTooFewPoints,
  kTooFewObstaclePoints,
  kTooFewKeypoints,  // fewer keypoints than must lie off the line
  kKeypointsOnLine,  // too few keypoints off the best line through them
};

std::string_view SuitabilityReasonName(SuitabilityReason reason);

struct SuitabilityResult {
  SuitabilityReason reason = SuitabilityReason::kSuitable;
  std::string message;          // what was counted against which threshold
  int64_t points = 0;           // finite cloud points
  int64_t obstacle_points = 0;  // finite obstacle points
  int64_t non_finite_points = 0;
  int64_t keypoints = 0;
  int64_t off_line_keypoints = -1;  // on the line that leaves the fewest off it; -1: not checked

  bool suitable() const { return reason == SuitabilityReason::kSuitable; }
};

class SubmapSuitability {
 public:
  explicit SubmapSuitability(const SuitabilityOptions& options = {}) : options_(options) {}

  // The size checks, done before keypoints are extracted.
  SuitabilityResult CheckCloud(const std::vector<CloudPoint>& points) const;
  // The spread of the keypoints (submap frame) about the line in xy that leaves the fewest off it.
  SuitabilityResult CheckKeypoints(const std::vector<Eigen::Vector3f>& keypoints) const;
  // Both: the cloud first, the keypoints when the cloud passes.
  SuitabilityResult Check(const Submap& submap, const std::vector<Eigen::Vector3f>& keypoints) const;

  // Keypoints farther than off_line_distance (xy) from the best RANSAC line; non-finite keypoints
  // are ignored.
  int64_t OffLineKeypoints(const std::vector<Eigen::Vector3f>& keypoints) const;

 private:
  SuitabilityOptions options_;
};

}  // namespace cairn
