#include "estimation/eval/team_agreement.h"

#include <algorithm>
#include <cmath>

#include "estimation/eval/team_evaluator.h"

namespace cairn {
namespace {

const Trajectory* Find(const TeamView& view, const std::string& robot) {
  for (const auto& [name, t] : view.robots) {
    if (name == robot) return &t;
  }
  return nullptr;
}

// The pose of `t` at `time` within `tolerance`, or null.
const StampedPose* At(const Trajectory& t, Timestamp time, Duration tolerance) {
  auto it = std::lower_bound(t.poses.begin(), t.poses.end(), time - tolerance,
                             [](const StampedPose& p, Timestamp x) { return p.time < x; });
  if (it == t.poses.end() || it->time > time + tolerance) return nullptr;
  return &*it;
}

}  // namespace

Expected<TeamAgreement> CompareTeamViews(const std::vector<TeamView>& views, double max_time_difference) {
  if (views.size() < 2) return InvalidArgumentError("graph agreement needs at least two views");
  TeamAgreement out;
  out.views = static_cast<int>(views.size());
  const TeamView& first = views.front();
  const Duration tolerance = Duration::Seconds(max_time_difference);
  for (size_t k = 1; k < views.size(); ++k) {
    const TeamView& view = views[k];
    // The first view plays ground truth for the team's alignment: one rigid transform per view.
    std::vector<TeamTrajectory> team;
    for (const auto& [robot, reference] : first.robots) {
      const Trajectory* other = Find(view, robot);
      if (other != nullptr && !reference.poses.empty() && !other->poses.empty()) {
        team.push_back(TeamTrajectory{robot, reference, *other});
      }
    }
    if (team.empty()) {
      return InvalidArgumentError("views " + first.viewer + " and " + view.viewer + " share no robot");
    }
    TrajectoryEvalOptions options;
    options.max_time_difference = max_time_difference;
    options.segment_lengths.clear();
    auto aligned = EvaluateTeam(team, options);
    if (!aligned.ok()) {
      return Status(aligned.status()).WithContext("views " + first.viewer + " and " + view.viewer);
    }
    for (const TeamTrajectory& r : team) {
      for (const StampedPose& p : r.estimate.poses) {
        const StampedPose* q = At(r.ground_truth, p.time, tolerance);
        if (q == nullptr) continue;
        const Eigen::Isometry3d T = aligned->T_gt_est * p.T_frame_body;
        const double dp = (T.translation() - q->T_frame_body.translation()).norm();
        const double dr = Eigen::AngleAxisd(q->T_frame_body.linear().transpose() * T.linear()).angle() * 180.0 / M_PI;
        ++out.compared_poses;
        if (dp > out.max_position) {
          out.max_position = dp;
          out.worst_viewer = view.viewer;
          out.worst_robot = r.robot;
        }
        out.max_rotation_deg = std::max(out.max_rotation_deg, dr);
      }
    }
  }
  return out;
}

}  // namespace cairn
