#pragma once
// What the matcher needs of one submap, computed once and reused for every pair it is in (thesis
// 6.1.1, 6.1.2): the suitability verdict, keypoints, their descriptors, the finite cloud for the
// ICP with its grey levels for the photometric check, and the xy box of the obstacle points for
// pairing. A submap the descriptors cannot use (few obstacles, keypoints on a line: most of a
// rover's on open ground) keeps its cloud when it covers enough ground for the grey-level search,
// which needs no obstacles (grey_level_search.h).

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
  // Ground seen from above (cells of 0.2 m, the search's raster, holding a point) that a submap
  // unsuitable for the descriptors must cover to be kept for the grey-level search; 0: never kept.
  double min_search_area = 8.0;

  void Visit(OptionsVisitor& v) {
    v.Section("suitability", suitability);
    v.Section("keypoints", keypoints);
    v.Section("descriptor", descriptor);
    v.Number("min_search_area", min_search_area, 0.0, 1e6, "m^2");
  }
};

struct SubmapFeatures {
  SuitabilityResult suitability;
  SubmapKeypoints keypoints;
  DescribedKeypoints described;         // empty for an unsuitable submap
  std::vector<Eigen::Vector3d> cloud;   // finite cloud points, submap frame; empty when unsuitable
  std::vector<float> cloud_grey;        // each cloud point's grey level (mean of r, g, b)
  // Unsuitable for the descriptors, yet kept (cloud and grey levels) for the grey-level search.
  bool searchable = false;
  double ground_area = 0.0;  // m^2 seen from above (min_search_area); 0 when not measured
  // xy extent of the finite obstacle points (submap frame); empty when there are none.
  Eigen::AlignedBox2d obstacle_box_xy;
  Eigen::AlignedBox2d cloud_box_xy;  // of every finite point
  std::vector<SubmapPlane> planes;  // the submap's planar faces (empty when unsuitable)
  std::vector<SubmapLine> lines;    // and its straight edges (the same)
  double keypoint_ms = 0.0;    // keypoints, known-space filter and suitability
  double descriptor_ms = 0.0;  // descriptors (zero for an unsuitable submap)

  bool suitable() const { return suitability.suitable(); }
  // The matcher can try it: with descriptors, or by the grey-level search alone.
  bool matchable() const { return suitable() || searchable; }
  // Where its matchable content lies, for the pairing's overlap: the obstacles a descriptor
  // match rests on, else the ground the search correlates.
  const Eigen::AlignedBox2d& match_box_xy() const { return suitable() ? obstacle_box_xy : cloud_box_xy; }
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
