#include "estimation/eval/team_evaluator.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cairn {
namespace {

Trajectory Line(double y, double heading, int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0.1 * i * std::cos(heading), y + 0.1 * i * std::sin(heading), 0.0);
    T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    t.poses.push_back(StampedPose{Timestamp::FromSeconds(100.0 + 0.1 * i), T});
  }
  return t;
}

Trajectory Moved(const Trajectory& t, const Eigen::Isometry3d& T) {
  Trajectory out = t;
  for (StampedPose& p : out.poses) p.T_frame_body = T * p.T_frame_body;
  return out;
}

TEST(TeamEvaluatorTest, ACommonFrameShiftAlignsAway) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(5, -3, 1);
  T.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  std::vector<TeamTrajectory> team = {{"a", Line(0, 0, 100), Moved(Line(0, 0, 100), T)},
                                      {"b", Line(4, 1.0, 100), Moved(Line(4, 1.0, 100), T)}};
  auto r = EvaluateTeam(team, TrajectoryEvalOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  ASSERT_EQ(r->robots.size(), 2u);
  for (const auto& [robot, e] : r->robots) EXPECT_LT(e.ate_rmse, 1e-6) << robot;
}

TEST(TeamEvaluatorTest, ARobotMisplacedRelativeToItsTeammateShowsItsError) {
  // b is off by 2 m relative to a: per-robot alignments would hide it, the team's cannot.
  Eigen::Isometry3d off = Eigen::Isometry3d::Identity();
  off.translation() = Eigen::Vector3d(0, 2, 0);
  std::vector<TeamTrajectory> team = {{"a", Line(0, 0, 200), Line(0, 0, 200)},
                                      {"b", Line(4, 0.5, 50), Moved(Line(4, 0.5, 50), off)}};
  auto r = EvaluateTeam(team, TrajectoryEvalOptions{});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_GT(r->robots[1].second.ate_rmse, 1.0);
  EXPECT_LT(r->robots[0].second.ate_rmse, 0.7);
  TrajectoryEvalOptions alone;
  auto b_alone = EvaluateTrajectory(team[1].ground_truth, team[1].estimate, alone);
  ASSERT_TRUE(b_alone.ok());
  EXPECT_LT(b_alone->ate_rmse, 1e-6);
}

TEST(TeamEvaluatorTest, NamesTheRobotThatDoesNotAssociate) {
  Trajectory late = Line(0, 0, 10);
  for (StampedPose& p : late.poses) p.time = p.time + Duration::Seconds(1000.0);
  std::vector<TeamTrajectory> team = {{"a", Line(0, 0, 100), Line(0, 0, 100)}, {"b", Line(1, 0, 10), late}};
  auto r = EvaluateTeam(team, TrajectoryEvalOptions{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().ToString().find("robot b"), std::string::npos) << r.status().ToString();
}

}  // namespace
}  // namespace cairn
