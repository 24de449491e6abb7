#pragma once
// Whether robots' graphs agree about the team. Each robot's graph (a "view") places every robot it
// knows in its own global frame (its own first origin), so views are compared after one rigid
// alignment per view onto the first view, fitted over every pose they share; what remains is the
// disagreement about where robots are relative to each other, which a lagging or diverging graph
// shows and a mere choice of frame does not.

#include <string>
#include <vector>

#include "common/status.h"
#include "estimation/eval/trajectory.h"

namespace cairn {

struct TeamView {
  std::string viewer;
  std::vector<std::pair<std::string, Trajectory>> robots;  // robot name -> its global trajectory, by time
};

struct TeamAgreement {
  int views = 0;
  int compared_poses = 0;            // poses of one robot at one time present in the first and another view
  double max_position = 0.0;         // m, worst pose over all views and robots after alignment
  double max_rotation_deg = 0.0;     // deg, worst pose
  std::string worst_viewer, worst_robot;  // where the worst position difference is
};

// Poses associate by robot and time (within `max_time_difference` s). Fails when fewer than two
// views are given or a view shares fewer than two poses with the first.
Expected<TeamAgreement> CompareTeamViews(const std::vector<TeamView>& views, double max_time_difference = 1e-3);

}  // namespace cairn
