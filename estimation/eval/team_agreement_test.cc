#include "estimation/eval/team_agreement.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

namespace cairn {
namespace {

Trajectory Arc(double y, double turn, int n) {
  Trajectory t;
  for (int i = 0; i < n; ++i) {
    const double heading = turn * i;
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0.2 * i, y + 0.01 * i * i * turn, 0.05 * std::sin(0.3 * i));
    T.linear() = Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    t.poses.push_back(StampedPose{Timestamp::FromSeconds(10.0 + 0.5 * i), T});
  }
  return t;
}

// The trajectory as a graph whose global frame is `T_view_world` away states it.
Trajectory InViewFrame(Trajectory t, const Eigen::Isometry3d& T_view_world) {
  std::for_each(t.poses.begin(), t.poses.end(), [&](StampedPose& p) { p.T_frame_body = T_view_world * p.T_frame_body; });
  return t;
}

Eigen::Isometry3d Frame(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(x, y, 0.3);
  T.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

TEST(TeamAgreementTest, ViewsInDifferentFramesOfTheSameTeamAgree) {
  const Trajectory a = Arc(0.0, 0.02, 60), b = Arc(5.0, -0.03, 40);
  std::vector<TeamView> views = {{"a", {{"a", a}, {"b", b}}},
                                 {"b", {{"a", InViewFrame(a, Frame(3, -2, 0.8))}, {"b", InViewFrame(b, Frame(3, -2, 0.8))}}},
                                 {"c", {{"b", InViewFrame(b, Frame(-1, 4, -2.0))}, {"a", InViewFrame(a, Frame(-1, 4, -2.0))}}}};
  auto r = CompareTeamViews(views);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->views, 3);
  EXPECT_EQ(r->compared_poses, 2 * (60 + 40));
  EXPECT_LT(r->max_position, 1e-9);
  EXPECT_LT(r->max_rotation_deg, 1e-6);
}

TEST(TeamAgreementTest, AViewThatPlacesATeammateElsewhereIsFound) {
  const Trajectory a = Arc(0.0, 0.02, 60), b = Arc(5.0, -0.03, 40);
  // View c holds b 5 mm and 0.05 deg off where a holds it: its graph has not caught up.
  Eigen::Isometry3d off = Frame(0.005, 0.0, 0.05 * M_PI / 180.0);
  off.translation().z() = 0.0;
  std::vector<TeamView> views = {{"a", {{"a", a}, {"b", b}}},
                                 {"c", {{"a", InViewFrame(a, Frame(1, 1, 0.3))}, {"b", InViewFrame(InViewFrame(b, off), Frame(1, 1, 0.3))}}}};
  auto r = CompareTeamViews(views);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_GT(r->max_position, 1e-3);
  EXPECT_GT(r->max_rotation_deg, 0.01);
  EXPECT_EQ(r->worst_viewer, "c");
}

TEST(TeamAgreementTest, OnlyPosesAtTheSameTimeAreCompared) {
  const Trajectory a = Arc(0.0, 0.02, 60);
  Trajectory late = a;
  late.poses.erase(late.poses.begin(), late.poses.begin() + 20);  // the other view lacks early poses
  std::vector<TeamView> views = {{"a", {{"a", a}}}, {"b", {{"a", late}}}};
  auto r = CompareTeamViews(views);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->compared_poses, 40);
}

TEST(TeamAgreementTest, NeedsTwoViewsThatShareARobot) {
  const Trajectory a = Arc(0.0, 0.02, 60);
  EXPECT_FALSE(CompareTeamViews({{"a", {{"a", a}}}}).ok());
  auto r = CompareTeamViews({{"a", {{"a", a}}}, {"b", {{"b", a}}}});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("share no robot"), std::string::npos) << r.status().ToString();
}

}  // namespace
}  // namespace cairn
