#include "daemon/pipeline/latency_histogram.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(LatencyHistogramTest, QuantilesWithinBucketResolution) {
  LatencyHistogram h;
  for (int i = 1; i <= 1000; ++i) h.Record(Duration::Microseconds(i));  // uniform 1 us .. 1 ms
  EXPECT_EQ(h.count(), 1000u);
  const double p50 = static_cast<double>(h.Quantile(0.5).nanoseconds()) / 1000.0;
  const double p99 = static_cast<double>(h.Quantile(0.99).nanoseconds()) / 1000.0;
  EXPECT_GE(p50, 500.0);
  EXPECT_LE(p50, 500.0 * 1.1);
  EXPECT_GE(p99, 990.0);
  EXPECT_LE(p99, 1000.0);  // capped by the exact maximum
  EXPECT_EQ(h.max(), Duration::Microseconds(1000));
  EXPECT_EQ(h.over_1ms(), 0u);  // 1 ms itself is in time
  h.Record(Duration::Nanoseconds(1'000'001));
  h.Record(Duration::Microseconds(1050));
  EXPECT_EQ(h.over_1ms(), 2u);
  EXPECT_GE(h.Quantile(0.999).nanoseconds(), 1'000'000);
}

TEST(LatencyHistogramTest, EmptyAndExtremes) {
  LatencyHistogram h;
  EXPECT_EQ(h.Quantile(0.5), Duration());
  h.Record(Duration::Nanoseconds(-5));  // clock oddities count as zero
  h.Record(Duration::Seconds(100.0));   // beyond the last bucket
  EXPECT_EQ(h.Quantile(1.0), Duration::Seconds(100.0));
  EXPECT_EQ(h.Quantile(0.0), Duration::Microseconds(1));
}

}  // namespace
}  // namespace cairn
