#include "daemon/comms/token_bucket.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(TokenBucketTest, MeanRateHoldsWithOverdraft) {
  TokenBucket bucket(1000.0, 500.0);
  Timestamp t = Timestamp::FromSeconds(10.0);
  size_t sent = 0;
  // 10 s of 300-byte messages sent whenever the balance allows.
  for (int i = 0; i < 10000; ++i) {
    while (bucket.Ready(t)) {
      bucket.Spend(t, 300);
      sent += 300;
    }
    t += Duration::Milliseconds(1);
  }
  // Burst (500) plus 10 s at 1000 B/s, overdrawn by at most one message.
  EXPECT_LE(sent, 500u + 10000u + 300u);
  EXPECT_GE(sent, 10000u);
}

TEST(TokenBucketTest, LargeMessageDelaysTheNext) {
  TokenBucket bucket(1000.0, 100.0);
  const Timestamp t = Timestamp::FromSeconds(1.0);
  ASSERT_TRUE(bucket.Ready(t));
  bucket.Spend(t, 5000);  // more than the burst: goes, and leaves a debt
  EXPECT_FALSE(bucket.Ready(t));
  const Duration wait = bucket.Wait(t);
  EXPECT_NEAR(wait.seconds(), 4.9, 0.01);
  EXPECT_FALSE(bucket.Ready(t + wait - Duration::Milliseconds(10)));
  EXPECT_TRUE(bucket.Ready(t + wait));
}

TEST(TokenBucketTest, BalanceNeverExceedsTheBurst) {
  TokenBucket bucket(1000.0, 100.0);
  EXPECT_DOUBLE_EQ(bucket.balance(Timestamp::FromSeconds(1.0)), 100.0);
  EXPECT_DOUBLE_EQ(bucket.balance(Timestamp::FromSeconds(100.0)), 100.0);
}

}  // namespace
}  // namespace cairn
