#pragma once
// `matching:` in a cairnd profile: submap matching (thesis 6.1) on the matcher pool. Finished
// submaps are paired by the graph's current estimates (eqs. 6.1 to 6.4), matched at low priority,
// and each match enters the graph as a factor c under the Cauchy loss.

#include <cstdint>

#include "common/options_visitor.h"
#include "daemon/pipeline/structure_landmark_options.h"
#include "mapping/matching/submap_feature_extractor.h"
#include "mapping/matching/submap_matcher.h"
#include "mapping/matching/submap_pairing.h"

namespace cairn {

struct SubmapMatchingOptions {
  bool enabled = false;
  int64_t workers = 1;  // matcher pool threads (executors.matcher schedules them)
  int64_t queue = 4;    // jobs handed to the pool and not yet finished
  // 4: the thesis' matcher on gravity-aligned submaps; 6: its variant without gravity, which finds
  // fewer matches (submap_matcher.h) and exists to measure that. Either way the graph takes the
  // match's x, y, z and yaw.
  ShotFrame dof = ShotFrame::kGravity;
  // Roll and pitch between two gravity-aligned origins, which a 4-DoF match does not measure.
  double tilt_sigma = 0.01;  // rad
  bool write_csv = true;            // OUT/matches.csv
  SubmapFeatureOptions features;
  SubmapPairingOptions pairing;
  SubmapMatcherOptions matcher;
  PlaneLandmarkOptions plane_landmarks;
  LineLandmarkOptions line_landmarks;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Integer("workers", workers, 1, 64, "threads");
    v.Integer("queue", queue, 1, 1024, "jobs");
    v.Choice("dof", dof, {{"4", ShotFrame::kGravity}, {"6", ShotFrame::kFull}});
    v.Number("tilt_sigma", tilt_sigma, 1e-6, 1.0, "rad");
    v.Flag("write_csv", write_csv);
    v.Section("features", features);
    v.Section("pairing", pairing);
    v.Section("matcher", matcher);
    v.Section("plane_landmarks", plane_landmarks);
    v.Section("line_landmarks", line_landmarks);
  }
};

}  // namespace cairn
