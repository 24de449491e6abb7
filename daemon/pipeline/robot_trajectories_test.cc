#include "daemon/pipeline/robot_trajectories.h"

#include <cmath>
#include <string>

#include <gtest/gtest.h>

#include "daemon/pipeline/team_input.h"

namespace cairn {
namespace {

PlacedEstimate TrajectoryEstimate(double t, uint64_t frame, double x, double yaw = 0.0) {
  PlacedEstimate e;
  e.time = Timestamp::FromSeconds(t);
  e.frame_id = frame;
  e.T_frame_body.translation() = Eigen::Vector3d(x, 0.0, 0.0);
  e.T_frame_body.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return e;
}

TEST(RobotTrajectoriesTest, TheOwnCurrentRunIsTheLatestAndTeamItemsNeverAddToIt) {
  RobotTrajectories t('a');
  EXPECT_EQ(t.Runs('a'), (std::vector<uint32_t>{kCurrentRun}));
  t.AddOwnEstimate(TrajectoryEstimate(1.0, 0, 0.0));
  t.AddTeamEstimate('a', 2, TrajectoryEstimate(0.5, RunIndex(2, 0), 0.0));
  t.AddTeamEstimate('a', kCurrentRun, TrajectoryEstimate(0.7, 0, 5.0));  // relayed back: not ours
  EXPECT_EQ(t.Runs('a'), (std::vector<uint32_t>{2, kCurrentRun}));
  ASSERT_EQ(t.Own().size(), 1u);
  EXPECT_EQ(t.Estimates('a', kCurrentRun), &t.Own());
  t.AddTeamEstimate('b', 3, TrajectoryEstimate(0.5, RunIndex(3, 0), 0.0));
  t.AddTeamEstimate('b', 1, TrajectoryEstimate(0.5, RunIndex(1, 0), 0.0));
  EXPECT_EQ(t.Runs('b'), (std::vector<uint32_t>{1, 3}));
  EXPECT_EQ(t.LatestRun('b'), 3u);
  EXPECT_EQ(t.Estimates('c', kCurrentRun), nullptr);
  EXPECT_GT(t.bytes(), 0u);
}

TEST(RobotTrajectoriesTest, ARestartedClockIsPlacedInTheRunBegunLast) {
  RobotTrajectories t('a');
  t.AddTeamEstimate('b', 1, TrajectoryEstimate(100.0, RunIndex(1, 0), 0.0));
  t.AddTeamEstimate('b', 2, TrajectoryEstimate(5.0, RunIndex(2, 0), 0.0));  // its clock started over
  EXPECT_EQ(t.RunAt('b', Timestamp::FromSeconds(50.0)), 2u);
  EXPECT_EQ(t.RunAt('b', Timestamp::FromSeconds(150.0)), 1u);
}

TEST(RobotTrajectoriesTest, PosesAreInterpolatedWithTheNearestGraphPosesCovariance) {
  RobotTrajectories t('a');
  t.AddOwnEstimate(TrajectoryEstimate(1.0, 0, 0.0, 0.0));
  t.AddOwnEstimate(TrajectoryEstimate(1.1, 0, 1.0, 0.2));
  PlacedEstimate pose;
  Matrix6d covariance;
  std::string why;
  // No graph pose at or after the time yet: the choice of covariance would not be settled.
  EXPECT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(1.05), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kWait);
  t.AddPoseCovariance('a', kCurrentRun, Timestamp::FromSeconds(1.0), 0, Matrix6d::Identity());
  t.AddPoseCovariance('a', kCurrentRun, Timestamp::FromSeconds(1.1), 0, 2.0 * Matrix6d::Identity());
  ASSERT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(1.075), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kReady);
  EXPECT_NEAR(pose.T_frame_body.translation().x(), 0.75, 1e-6);
  EXPECT_NEAR(Eigen::AngleAxisd(pose.T_frame_body.linear()).angle(), 0.15, 1e-6);
  EXPECT_EQ(covariance(0, 0), 2.0);
  // Beyond the last estimate: it waits for more.
  EXPECT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(1.2), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kWait);
}

TEST(RobotTrajectoriesTest, GapsFrameSwitchesAndEarlyTimesAreNeverPlaced) {
  RobotTrajectories t('a');
  t.AddOwnEstimate(TrajectoryEstimate(1.0, 0, 0.0));
  t.AddOwnEstimate(TrajectoryEstimate(2.0, 0, 1.0));  // after a gap of 1 s
  t.AddOwnEstimate(TrajectoryEstimate(2.3, 1, 0.0));  // a frame switch between 2.0 and 2.3
  t.AddOwnEstimate(TrajectoryEstimate(2.4, 1, 0.1));
  t.AddPoseCovariance('a', kCurrentRun, Timestamp::FromSeconds(2.4), 1, Matrix6d::Identity());
  PlacedEstimate pose;
  Matrix6d covariance;
  std::string why;
  EXPECT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(0.5), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kNever);
  EXPECT_NE(why.find("no estimate of a before"), std::string::npos) << why;
  EXPECT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(1.5), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kNever);
  EXPECT_NE(why.find("a gap"), std::string::npos) << why;
  EXPECT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(2.15), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kNever);
  EXPECT_NE(why.find("a frame switch"), std::string::npos) << why;
  // Near the switch: the nearer estimate, in its own frame.
  ASSERT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(2.28), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kReady);
  EXPECT_EQ(pose.frame_id, 1u);
  // A graph pose of another frame does not give the covariance.
  EXPECT_EQ(t.PoseAt('a', kCurrentRun, Timestamp::FromSeconds(2.0), &pose, &covariance, &why),
            RobotTrajectories::Lookup::kNever);
  EXPECT_NE(why.find("no graph pose of a"), std::string::npos) << why;
}

}  // namespace
}  // namespace cairn
