#pragma once
// A search for 4-DoF alignments of two gravity-aligned submaps by their grey levels seen from
// above. Where the obstacles are few and lie on crater rims, the descriptors often yield no vote
// cluster near the truth, while the ground's albedo pattern tells true from wrong alignments well
// (photometric_agreement.h). This search needs no keypoints: for every yaw step it rasterizes B's
// grey levels turned by that yaw, removes each raster's local mean (shading, the cameras' gain and
// offset), and correlates it with A's raster over every xy shift at once by FFT. The best
// alignments, far enough apart, are hypotheses for the matcher's usual checks and ICP. z comes
// from the median height difference over the overlap.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "common/status.h"
#include "mapping/matching/four_dof_transform.h"

namespace cairn {

struct GreyLevelSearchOptions {
  // Off: the matcher's hypotheses come from the descriptors only (the thesis' pipeline).
  bool enabled = true;
  double cell = 0.2;                // m; raster resolution
  double yaw_step = 0.052;          // rad; 3 deg: at 5 m from the origin 0.13 m off, within the ICP's reach
  double local_mean_radius = 0.4;   // m; half width of the window whose mean each cell loses
  int64_t min_overlap_cells = 100;  // textured cells both rasters share (4 m^2 at 0.2 m)
  double min_correlation = 0.6;     // of the rasters under a candidate
  // The grey levels' correlation a refined candidate needs (the matcher's min_match_ncc, if
  // higher, applies too): a search picks the best of many alignments, so the grey levels that
  // chose it must vouch for it more than for a hypothesis the descriptors found.
  double min_match_ncc = 0.95;
  int64_t max_candidates = 3;  // handed to the matcher, best first
  // Candidates closer to a better one than this are the same peak.
  double separation_translation = 0.5;  // m
  double separation_yaw = 0.2;          // rad

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("cell", cell, 0.01, 2.0, "m");
    v.Number("yaw_step", yaw_step, 0.001, 0.5, "rad");
    v.Number("local_mean_radius", local_mean_radius, 0.0, 10.0, "m");
    v.Integer("min_overlap_cells", min_overlap_cells, 10, 100'000'000, "cells");
    v.Number("min_correlation", min_correlation, -1.0, 1.0, "correlation");
    v.Number("min_match_ncc", min_match_ncc, -1.0, 1.0, "correlation");
    v.Integer("max_candidates", max_candidates, 1, 100, "");
    v.Number("separation_translation", separation_translation, 0.0, 100.0, "m");
    v.Number("separation_yaw", separation_yaw, 0.0, 3.2, "rad");
  }
};

struct GreyLevelCandidate {
  FourDofTransform T_a_b;
  double correlation = 0.0;  // of the two rasters' local deviations
  int64_t overlap_cells = 0;
};

struct GreyLevelSearchResult {
  std::vector<GreyLevelCandidate> candidates;  // best first
  int64_t yaws = 0;                            // yaw steps searched
  double ms = 0.0;
};

class GreyLevelSearch {
 public:
  explicit GreyLevelSearch(const GreyLevelSearchOptions& options = {}) : options_(options) {}

  // Candidates for T_a_b between two clouds with one grey level per point (the shorter of cloud
  // and grey decides; non-finite values are skipped). Refused only for options out of range or
  // rasters beyond a sane size; no candidate is not an error.
  // `yaw_window` (centre, half width in rad) limits the yaws searched, e.g. to the gate around the
  // graph's relative estimate: its centre and steps from it, to half a step beyond the half width.
  // Half width >= pi searches all. A candidate's xy is the peak's cell, so it may be off by half a
  // cell, and by the yaw's error times its distance from B's origin (SearchSlack).
  Expected<GreyLevelSearchResult> Search(const std::vector<Eigen::Vector3d>& cloud_a,
                                         const std::vector<float>& grey_a,
                                         const std::vector<Eigen::Vector3d>& cloud_b,
                                         const std::vector<float>& grey_b,
                                         Eigen::Vector2d yaw_window = {0.0, 4.0}) const;

  // How far (m, rad) a candidate may lie from the true alignment by the search's steps alone,
  // for B's cloud: half a cell's diagonal plus half a yaw step times the distance of B's centroid
  // from its origin, and half a yaw step. A gate applied to a candidate before its refinement
  // widens by this much.
  Eigen::Vector2d SearchSlack(const std::vector<Eigen::Vector3d>& cloud_b) const;

 private:
  GreyLevelSearchOptions options_;
};

}  // namespace cairn
