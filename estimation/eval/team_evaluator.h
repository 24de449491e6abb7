#pragma once
// Accuracy of a team's trajectories the way multi-robot SLAM is scored: one alignment for the whole
// team (estimated from every robot's associated poses at once), then each robot's absolute
// trajectory error under it. A robot placed wrongly relative to its teammates shows up as a large
// error of its own, which separate per-robot alignments would hide.

#include <string>
#include <vector>

#include "common/status.h"
#include "estimation/eval/trajectory_evaluator.h"

namespace cairn {

struct TeamTrajectory {
  std::string robot;
  Trajectory ground_truth;  // all in one world frame
  Trajectory estimate;      // all in one estimated frame
};

struct TeamEvalResult {
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();
  int associated = 0;
  std::vector<std::pair<std::string, TrajectoryEvalResult>> robots;  // under the team alignment
};

// `options.alignment` is the team's (SE(3) or 4-DoF); per-robot results carry no alignment of their
// own. Fails naming the robot whose trajectories do not associate.
Expected<TeamEvalResult> EvaluateTeam(const std::vector<TeamTrajectory>& team, const TrajectoryEvalOptions& options);

}  // namespace cairn
