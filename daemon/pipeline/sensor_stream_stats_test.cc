#include "daemon/pipeline/sensor_stream_stats.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

Timestamp AtMs(int64_t ms) { return Timestamp::FromNanoseconds(ms * 1000000); }

TEST(SensorStreamStatsTest, CountsRateGapsDuplicatesAndOutOfOrder) {
  SensorStreamStats s(100.0);  // 10 ms period; gaps above 15 ms
  for (int64_t t : {0, 10, 20, 30, 60, 60, 50, 70}) s.Add(AtMs(t));
  EXPECT_EQ(s.count(), 8u);
  EXPECT_EQ(s.duplicates(), 1u);
  EXPECT_EQ(s.out_of_order(), 1u);
  EXPECT_EQ(s.gaps(), 1u);
  EXPECT_DOUBLE_EQ(s.max_gap(), 0.030);
  EXPECT_EQ(s.last(), AtMs(70));
  EXPECT_DOUBLE_EQ(s.duration(), 0.070);
  EXPECT_NEAR(s.mean_rate_hz(), 5.0 / 0.070, 1e-9);  // six in-order samples
}

TEST(SensorStreamStatsTest, EmptyAndSingleSampleStreams) {
  SensorStreamStats s;
  EXPECT_EQ(s.mean_rate_hz(), 0.0);
  s.Add(AtMs(5));
  EXPECT_EQ(s.duration(), 0.0);
  EXPECT_EQ(s.mean_rate_hz(), 0.0);
  EXPECT_EQ(s.gaps(), 0u);
}

}  // namespace
}  // namespace cairn
