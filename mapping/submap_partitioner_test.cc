#include "mapping/submap_partitioner.h"

#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

struct Recorder : FrameSwitchRequesterInterface {
  std::vector<FrameSwitchRequest> requests;
  void RequestFrameSwitch(const FrameSwitchRequest& r) override { requests.push_back(r); }
};

Timestamp T(double s) { return Timestamp::FromSeconds(s); }

TEST(SubmapPartitionerTest, DistanceCriterionTriggersOnceUntilTheFrameSwitches) {
  Recorder rec;
  SubmapPartitioner part(PartitionOptions{}, &rec);
  const Eigen::Matrix3d cov = Eigen::Matrix3d::Identity() * 1e-4;  // sigma 0.01 m
  int t = 0;
  for (double x = 0.0; x <= 6.9; x += 0.1) EXPECT_FALSE(part.Update(T(t++ * 0.1), 1, {x, 0, 0}, cov));
  EXPECT_TRUE(part.Update(T(t++ * 0.1), 1, {7.05, 0, 0}, cov));
  ASSERT_EQ(rec.requests.size(), 1u);
  EXPECT_EQ(rec.requests[0].reason, PartitionReason::kDistance);
  EXPECT_EQ(rec.requests[0].frame_id, 1u);
  EXPECT_NEAR(rec.requests[0].distance, 7.05, 1e-9);
  // No repeat within the retry interval, a repeat after it.
  EXPECT_FALSE(part.Update(T(7.2), 1, {7.1, 0, 0}, cov));
  EXPECT_TRUE(part.Update(T(8.2), 1, {7.2, 0, 0}, cov));
  // The new frame restarts the distance.
  EXPECT_FALSE(part.Update(T(8.3), 2, {0, 0, 0}, cov));
  EXPECT_DOUBLE_EQ(part.distance(), 0.0);
  EXPECT_EQ(rec.requests.size(), 2u);
}

TEST(SubmapPartitionerTest, PositionSigmaCriterionUsesTheLargestStandardDeviation) {
  Recorder rec;
  PartitionOptions o;
  o.max_position_sigma = 0.1;
  SubmapPartitioner part(o, &rec);
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity() * 0.0081;  // 0.09 m
  EXPECT_FALSE(part.Update(T(0), 4, {0, 0, 0}, cov));
  // Correlated x/y: each axis 0.09 m but along the diagonal sqrt(0.0081 + 0.006) = 0.119 m.
  cov(0, 1) = cov(1, 0) = 0.006;
  EXPECT_TRUE(part.Update(T(1), 4, {0, 0, 0}, cov));
  ASSERT_EQ(rec.requests.size(), 1u);
  EXPECT_EQ(rec.requests[0].reason, PartitionReason::kPositionSigma);
  EXPECT_NEAR(rec.requests[0].position_sigma, std::sqrt(0.0141), 1e-9);
}

}  // namespace
}  // namespace cairn
