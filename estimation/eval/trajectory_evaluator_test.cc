#include "estimation/eval/trajectory_evaluator.h"

#include <cmath>

#include <gtest/gtest.h>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

// A 10 m arc at 10 Hz, turning as it goes (or a straight line, still turning).
Trajectory GroundTruth(bool straight = false) {
  Trajectory t;
  for (int i = 0; i <= 100; ++i) {
    StampedPose p;
    p.time = Timestamp::FromNanoseconds(1'000'000'000LL + i * 100'000'000LL);
    const double a = 0.03 * i;
    p.T_frame_body.linear() = so3::Exp(Eigen::Vector3d(0.0, 0.0, a));
    p.T_frame_body.translation() = straight ? Eigen::Vector3d(0.1 * i, 0.0, 0.01 * i)
                                            : Eigen::Vector3d(3.0 * std::sin(a), 3.0 * (1.0 - std::cos(a)), 0.01 * i);
    t.poses.push_back(p);
  }
  return t;
}

TEST(TrajectoryEvaluatorTest, RigidlyMovedCopyHasNoErrorAfterAlignment) {
  const Trajectory gt = GroundTruth();
  Trajectory est = gt;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(Eigen::Vector3d(0.0, 0.0, 1.0));  // yaw only: 4-DoF aligns it too
  T.translation() = Eigen::Vector3d(5.0, -2.0, 1.0);
  for (StampedPose& p : est.poses) p.T_frame_body = T * p.T_frame_body;
  for (TrajectoryAlignment a : {TrajectoryAlignment::kSe3, TrajectoryAlignment::kFourDof}) {
    TrajectoryEvalOptions o;
    o.alignment = a;
    const auto r = EvaluateTrajectory(gt, est, o);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->associated, 101);
    EXPECT_LT(r->ate_rmse, 1e-9);
    EXPECT_LT(r->segments[0].translation_percent, 1e-7);
    EXPECT_GT(r->segments[0].pairs, 50);
    EXPECT_LT(r->drift_translation, 1e-9);
  }
  TrajectoryEvalOptions none;
  none.alignment = TrajectoryAlignment::kNone;
  const auto r = EvaluateTrajectory(gt, est, none);
  ASSERT_TRUE(r.ok());
  EXPECT_GT(r->ate_rmse, 1.0);
  // Relative errors do not depend on the alignment.
  EXPECT_LT(r->segments[0].translation_percent, 1e-7);
}

TEST(TrajectoryEvaluatorTest, KnownScaleErrorGivesKnownRelativeError) {
  const Trajectory gt = GroundTruth(true);
  Trajectory est = gt;
  // 1 % too long everywhere on a straight path: the RPE translation is 1 % of the distance.
  for (StampedPose& p : est.poses) p.T_frame_body.translation() *= 1.01;
  const auto r = EvaluateTrajectory(gt, est, TrajectoryEvalOptions{});
  ASSERT_TRUE(r.ok());
  for (const SegmentError& s : r->segments) {
    if (s.pairs == 0) continue;
    EXPECT_NEAR(s.translation_percent, 1.0, 0.02) << s.length;
    EXPECT_LT(s.rotation_deg_per_m, 1e-9);
  }
  EXPECT_NEAR(r->drift_translation, 0.01 * (gt.poses.front().T_frame_body.inverse() * gt.poses.back().T_frame_body).translation().norm(), 0.02);
}

TEST(TrajectoryEvaluatorTest, MismatchedTimesAndBadNamesAreErrors) {
  const Trajectory gt = GroundTruth();
  Trajectory est = gt;
  for (StampedPose& p : est.poses) p.time = p.time + Duration::Seconds(1000.0);
  const auto r = EvaluateTrajectory(gt, est, TrajectoryEvalOptions{});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("ground-truth pose within"), std::string::npos) << r.status().message();
  EXPECT_FALSE(ParseTrajectoryAlignment("sim3").ok());
  EXPECT_TRUE(ParseTrajectoryAlignment("4dof").ok());
}

}  // namespace
}  // namespace cairn
