#include "common/timestamp.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(TimestampTest, ArithmeticKeepsNanosecondsExact) {
  const Timestamp t = Timestamp::FromNanoseconds(1403715273262142976);
  const Timestamp u = t + Duration::Milliseconds(50);
  EXPECT_EQ((u - t).nanoseconds(), 50000000);
  EXPECT_EQ(u.nanoseconds(), 1403715273312142976);
  EXPECT_LT(t, u);
}

TEST(TimestampTest, SecondsRoundToNearestNanosecond) {
  EXPECT_EQ(Duration::Seconds(0.0000000014).nanoseconds(), 1);
  EXPECT_EQ(Duration::Seconds(-0.0000000016).nanoseconds(), -2);
  EXPECT_EQ(Timestamp::FromSeconds(1.5).nanoseconds(), 1500000000);
  EXPECT_DOUBLE_EQ(Duration::Milliseconds(5).seconds(), 0.005);
}

}  // namespace
}  // namespace cairn
