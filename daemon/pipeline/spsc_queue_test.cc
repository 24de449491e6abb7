#include "daemon/pipeline/spsc_queue.h"

#include <thread>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(SpscQueueTest, FullQueueDropsNewItemsAndCountsThem) {
  SpscQueue<int> q(3);  // rounded up to 4
  EXPECT_EQ(q.capacity(), 4u);
  for (int i = 0; i < 6; ++i) q.TryPush(i);
  EXPECT_EQ(q.size(), 4u);
  EXPECT_EQ(q.dropped(), 2u);
  EXPECT_EQ(q.high_water(), 4u);
  EXPECT_EQ(*q.Front(), 0);
  q.PopFront();
  EXPECT_EQ(*q.Front(), 1);
}

// One producer and one consumer hammer the ring; every item arrives once, in order, and the
// pushed/dropped/popped accounting balances.
TEST(SpscQueueTest, ConcurrentProducerConsumerKeepOrderAndAccounting) {
  SpscQueue<uint64_t> q(64);
  WorkSignal signal;
  constexpr uint64_t kItems = 200000;
  std::atomic<bool> done{false};
  uint64_t received = 0, last = 0;
  bool ordered = true;
  std::thread consumer([&] {
    while (true) {
      const uint32_t seen = signal.sequence();
      bool worked = false;
      while (const uint64_t* v = q.Front()) {
        if (received > 0 && *v <= last) ordered = false;
        last = *v;
        ++received;
        q.PopFront();
        worked = true;
      }
      if (done.load() && q.empty()) return;
      if (!worked) signal.WaitChange(seen);
    }
  });
  uint64_t accepted = 0;
  for (uint64_t i = 1; i <= kItems; ++i) {
    if (q.TryPush(i)) ++accepted;
    signal.Notify();
  }
  done.store(true);
  signal.Notify();
  consumer.join();
  EXPECT_TRUE(ordered);
  EXPECT_EQ(received, accepted);
  EXPECT_EQ(accepted + q.dropped(), kItems);
  EXPECT_EQ(q.popped(), accepted);
}

}  // namespace
}  // namespace cairn
