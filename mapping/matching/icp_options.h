#pragma once
// Options of the matcher's point-to-plane ICP (four_dof_icp.h explains each; the 6-DoF variant,
// six_dof_icp.h, reads yaw_tolerance as its tolerance on any rotation).

#include <cstdint>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

struct IcpOptions {
  int64_t max_iterations = 50;
  double max_correspondence_distance = 1.0;   // m; gate of the first iteration
  double min_correspondence_distance = 0.15;  // m; the gate's floor
  double gate_shrink = 0.6;                   // gate factor per iteration
  int64_t normal_neighbours = 12;             // k of the target's local PCA
  double normal_radius = 0.3;                 // m; farther neighbours do not count
  int64_t min_normal_neighbours = 6;
  double max_surface_variation = 0.05;  // lambda_0 / (lambda_0 + lambda_1 + lambda_2)
  double min_planar_ratio = 0.05;       // lambda_1 / lambda_2
  bool unique_targets = true;           // one source point per target point (see above)
  int64_t min_correspondences = 100;    // fewer overlapping points is a failure
  double min_observability = 0.001;     // see the header comment
  double translation_tolerance = 1e-5;  // m
  double yaw_tolerance = 1e-6;          // rad
  double max_step_sigmas = 0.05;        // step^T Sigma^-1 step below its square
  int64_t freeze_after = 5;             // passes at the gate's minimum before the pairs are kept

  void Visit(OptionsVisitor& v) {
    v.Integer("max_iterations", max_iterations, 1, 10'000, "");
    v.Number("max_correspondence_distance", max_correspondence_distance, 1e-3, 100.0, "m");
    v.Number("min_correspondence_distance", min_correspondence_distance, 1e-3, 100.0, "m");
    v.Number("gate_shrink", gate_shrink, 0.05, 1.0, "");
    v.Integer("normal_neighbours", normal_neighbours, 3, 256, "");
    v.Number("normal_radius", normal_radius, 1e-3, 10.0, "m");
    v.Integer("min_normal_neighbours", min_normal_neighbours, 3, 256, "");
    v.Number("max_surface_variation", max_surface_variation, 0.0, 1.0 / 3.0, "");
    v.Number("min_planar_ratio", min_planar_ratio, 0.0, 1.0, "");
    v.Flag("unique_targets", unique_targets);
    v.Integer("min_correspondences", min_correspondences, 5, 100'000'000, "");
    v.Number("min_observability", min_observability, 0.0, 1.0, "");
    v.Number("translation_tolerance", translation_tolerance, 0.0, 1.0, "m");
    v.Number("yaw_tolerance", yaw_tolerance, 0.0, 1.0, "rad");
    v.Number("max_step_sigmas", max_step_sigmas, 0.0, 1.0, "");
    v.Integer("freeze_after", freeze_after, 1, 10'000, "");
  }
  Status Validate() const;
};

}  // namespace cairn
