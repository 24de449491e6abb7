#include "estimation/eval/team_evaluator.h"

namespace cairn {

Expected<TeamEvalResult> EvaluateTeam(const std::vector<TeamTrajectory>& team, const TrajectoryEvalOptions& options) {
  if (team.empty()) return InvalidArgumentError("no robots to evaluate");
  // One trajectory pair of the whole team: each robot's poses moved to a time span of their own,
  // so that association stays within a robot while the alignment sees them all.
  const Duration span = Duration::Seconds(1e7);
  Trajectory gt, est;
  for (size_t i = 0; i < team.size(); ++i) {
    const Duration shift = span * static_cast<int64_t>(i);
    for (const StampedPose& p : team[i].ground_truth.poses) gt.poses.push_back(StampedPose{p.time + shift, p.T_frame_body});
    for (const StampedPose& p : team[i].estimate.poses) est.poses.push_back(StampedPose{p.time + shift, p.T_frame_body});
  }
  TeamEvalResult result;
  auto joint = EvaluateTrajectory(gt, est, options);
  if (!joint.ok()) return Status(joint.status()).WithContext("the team's trajectories");
  result.T_gt_est = joint->T_gt_est;
  result.associated = joint->associated;
  TrajectoryEvalOptions each = options;
  each.alignment = TrajectoryAlignment::kNone;
  for (const TeamTrajectory& r : team) {
    Trajectory aligned = r.estimate;
    for (StampedPose& p : aligned.poses) p.T_frame_body = result.T_gt_est * p.T_frame_body;
    auto e = EvaluateTrajectory(r.ground_truth, aligned, each);
    if (!e.ok()) return Status(e.status()).WithContext("robot " + r.robot);
    result.robots.emplace_back(r.robot, *e);
  }
  return result;
}

}  // namespace cairn
