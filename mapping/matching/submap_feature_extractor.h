#pragma once
// What the matcher needs of one submap, computed once and reused for every pair it is in (thesis
// 6.1.1, 6.1.2): the suitability verdict, keypoints, their descriptors, the finite cloud for the
// ICP with its grey levels for the photometric check, and the xy box of the obstacle points for
// pairing.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "mapping/matching/gravity_shot_descriptor.h"
#include "mapping/matching/keypoint_extractor.h"
#include "mapping/matching/submap_suitability.h"
#include "mapping/submap.h"

namespace cairn {

struct SubmapFeatureOptions {
  SuitabilityOptions suitability;
  KeypointExtractorOptions keypoints;
  GravityShotOptions descriptor;

  void Visit(OptionsVisitor& v) {
    v.Section("suitability", suitability);
    v.Section("keypoints", keypoints);
    v.Section("descriptor", descriptor);
  }
};

struct SubmapFeatures {
  SuitabilityResult suitability;
  SubmapKeypoints keypoints;
  DescribedKeypoints described;         // empty for an unsuitable submap
  std::vector<Eigen::Vector3d> cloud;   // finite cloud points, submap frame; empty when unsuitable
  std::vector<float> cloud_grey;        // each cloud point's grey level (mean of r, g, b)
  // xy extent of the finite obstacle points (submap frame); empty when there are none.
  Eigen::AlignedBox2d obstacle_box_xy;
  std::vector<SubmapPlane> planes;  // the submap's planar faces (empty when unsuitable)
  std::vector<SubmapLine> lines;    // and its straight edges (the same)
  double keypoint_ms = 0.0;    // keypoints, known-space filter and suitability
  double descriptor_ms = 0.0;  // descriptors (zero for an unsuitable submap)

  bool suitable() const { return suitability.suitable(); }
  size_t memory_bytes() const;  // heap held by the vectors above
};

class SubmapFeatureExtractor {
 public:
  // kFull: descriptors for the matcher's 6-DoF variant (gravity_shot_descriptor.h).
  explicit SubmapFeatureExtractor(const SubmapFeatureOptions& options = {}, ShotFrame frame = ShotFrame::kGravity)
      : options_(options), frame_(frame) {}

  // Never fails: a submap that cannot be matched (too small, keypoints on a line, nothing
  // finite) comes back unsuitable with the reason, and without descriptors.
  SubmapFeatures Extract(const Submap& submap) const;

 private:
  SubmapFeatureOptions options_;
  ShotFrame frame_;
};

}  // namespace cairn
