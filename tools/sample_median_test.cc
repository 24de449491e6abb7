#include "tools/sample_median.h"

#include <cmath>

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
}  // namespace cairn
