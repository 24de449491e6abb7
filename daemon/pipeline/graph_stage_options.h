#pragma once
// `graph:` in a cairnd profile: the robot's SLAM graph (thesis 4.2, filter topology of Fig. 4.2b)
// built online from the filter's frame switches (w: submap origin -> next origin) and sparse
// robot poses (v: origin -> pose), optimized on the graph executor. Its origins place the global
// trajectory and the graph is exported as g2o at the end of a run.

#include <cstdint>

#include "common/options_visitor.h"
#include "daemon/pipeline/gnss_fix_factors.h"
#include "estimation/graph/slam_graph.h"
#include "estimation/graph/team_match_screen.h"

namespace cairn {

struct GraphStageOptions {
  bool enabled = false;
  // Every Nth valid filter estimate becomes a robot pose variable x with its v factor.
  int64_t pose_every = 10;
  // Floors added to covariances before they are inverted: the filter's pose right after a frame
  // switch, and a switch's roll and pitch, are known almost exactly, which would make the
  // information matrix singular. Also the sigmas of the prior on the first origin.
  double min_position_sigma = 0.001;  // m
  double min_rotation_sigma = 0.001;  // rad
  bool write_g2o = true;              // OUT/graph.g2o at the end
  SlamGraphOptions optimizer;
  // Matches between two robots are tested against each other before they enter (a wrong first
  // tie cannot be undone by the graph's robust loss).
  TeamMatchScreenOptions team_matches;
  GnssFixOptions gnss;  // fixes as factors on the team's datum (off by default)

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Integer("pose_every", pose_every, 1, 100000, "estimates");
    v.Number("min_position_sigma", min_position_sigma, 1e-6, 1.0, "m");
    v.Number("min_rotation_sigma", min_rotation_sigma, 1e-6, 1.0, "rad");
    v.Flag("write_g2o", write_g2o);
    v.Section("optimizer", optimizer);
    v.Section("team_matches", team_matches);
    v.Section("gnss", gnss);
  }
};

}  // namespace cairn
