#pragma once
// Keypoint correspondences between two submaps by descriptor distance (thesis 6.1.2): for each
// keypoint of A the k most similar keypoints of B, and for each of B the k most similar of A,
// under a similarity threshold, duplicates removed.
//
// The search is brute force: the descriptors have 512 dimensions, where a k-d tree visits nearly
// every leaf anyway, while all squared distances of a block of A against all of B are one matrix
// product (|a|^2 + |b|^2 - 2 a.b) that Eigen runs at full SIMD width.

#include <cstdint>
#include <vector>

#include "common/options_visitor.h"
#include "mapping/matching/gravity_shot_descriptor.h"

namespace cairn {

struct CorrespondenceFinderOptions {
  int64_t matches_per_keypoint = 3;
  // Largest GravityShotDescriptor::Distance (in [0, 1]) of a correspondence (thesis: 0.5).
  double max_distance = 0.5;
  // false: a pair among A's k best for its A keypoint or among B's k best for its B keypoint
  // (thesis); true: among both.
  bool mutual_only = false;

  void Visit(OptionsVisitor& v) {
    v.Integer("matches_per_keypoint", matches_per_keypoint, 1, 100, "");
    v.Number("max_distance", max_distance, 0.0, 1.0, "");
    v.Flag("mutual_only", mutual_only);
  }
};

struct KeypointCorrespondence {
  uint32_t a = 0;         // index into A's described keypoints
  uint32_t b = 0;         // index into B's
  float distance = 0.0f;  // descriptor distance in [0, 1]
  float score = 0.0f;     // 1 - distance, or as a later stage set it
};

class CorrespondenceFinder {
 public:
  explicit CorrespondenceFinder(const CorrespondenceFinderOptions& options = {}) : options_(options) {}

  // Sorted by (a, b).
  std::vector<KeypointCorrespondence> Find(const std::vector<GravityShot>& a,
                                           const std::vector<GravityShot>& b) const;

 private:
  CorrespondenceFinderOptions options_;
};

}  // namespace cairn
