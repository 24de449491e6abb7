#include "tools/sample_median.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(SampleMedianTest, OddEvenAndEmptySamples) {
  EXPECT_DOUBLE_EQ(Median({5.0, 1.0, 3.0}), 3.0);
  EXPECT_DOUBLE_EQ(Median({4.0, 1.0, 3.0, 2.0}), 2.5);
  EXPECT_DOUBLE_EQ(Median({7.0}), 7.0);
  EXPECT_TRUE(std::isnan(Median({})));
}

}  // namespace
TEST(SampleMedianTest, NearestRankPercentiles) {
  const std::vector<double> v{5.0, 1.0, 4.0, 2.0, 3.0, 10.0, 9.0, 8.0, 7.0, 6.0};
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.0), 1.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.5), 5.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.9), 9.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 0.91), 10.0);
  EXPECT_DOUBLE_EQ(NearestRankPercentile(v, 1.0), 10.0);
  EXPECT_TRUE(std::isnan(NearestRankPercentile({}, 0.5)));
}

}  // namespace cairn
