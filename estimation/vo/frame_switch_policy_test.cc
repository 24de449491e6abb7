#include "estimation/vo/frame_switch_policy.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(FrameSwitchPolicyTest, SwitchesAfterDistanceOrSigmaOncePerFrame) {
  FrameSwitchOptions o;
  FrameSwitchPolicy p(o);
  EXPECT_EQ(p.Update(0, Eigen::Vector3d::Zero(), 0.0), FrameSwitchReason::kNone);
  for (int i = 1; i <= 69; ++i) {
    EXPECT_EQ(p.Update(0, Eigen::Vector3d(0.1 * i, 0, 0), 0.01), FrameSwitchReason::kNone) << i;
  }
  EXPECT_EQ(p.Update(0, Eigen::Vector3d(7.0, 0, 0), 0.01), FrameSwitchReason::kDistance);
  // Asked once; waits for the new frame.
  EXPECT_EQ(p.Update(0, Eigen::Vector3d(7.1, 0, 0), 0.5), FrameSwitchReason::kNone);
  EXPECT_EQ(p.Update(1, Eigen::Vector3d::Zero(), 0.0), FrameSwitchReason::kNone);
  EXPECT_NEAR(p.distance(), 0.0, 1e-12);
  EXPECT_EQ(p.Update(1, Eigen::Vector3d(0.1, 0, 0), 0.11), FrameSwitchReason::kPositionSigma);
  FrameSwitchOptions off;
  off.enabled = false;
  FrameSwitchPolicy q(off);
  EXPECT_EQ(q.Update(0, Eigen::Vector3d::Zero(), 1.0), FrameSwitchReason::kNone);
}

}  // namespace
}  // namespace cairn
