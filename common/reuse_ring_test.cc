#include "common/reuse_ring.h"

#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(ReuseRingTest, FirstInFirstOutUpToItsSize) {
  ReuseRing<int, 3> ring;
  EXPECT_TRUE(ring.empty());
  for (int k = 0; k < 3; ++k) {
    ring.Next() = k;
    ring.Push();
  }
  EXPECT_TRUE(ring.full());
  EXPECT_EQ(ring.Front(), 0);
  ring.Pop();
  ring.Next() = 3;  // wraps round into the first slot
  ring.Push();
  std::vector<int> out;
  while (!ring.empty()) {
    out.push_back(ring.Front());
    ring.Pop();
  }
  EXPECT_EQ(out, (std::vector<int>{1, 2, 3}));
}

TEST(ReuseRingTest, TheSlotGivenUpLastIsReusedFirst) {
  ReuseRing<std::vector<float>, 4> ring;
  ring.Next().assign(1000, 1.0f);
  ring.Push();
  const float* first = ring.Front().data();
  ring.Pop();
  std::vector<float>& again = ring.Next();
  EXPECT_GE(again.capacity(), 1000u);
  again.resize(1000);
  EXPECT_EQ(again.data(), first);
}

TEST(ReuseRingTest, OnlyAsManySlotsGrowAsElementsAreHeldAtOnce) {
  ReuseRing<std::vector<float>, 16> ring;
  int grown = 0;
  auto put = [&] {
    std::vector<float>& v = ring.Next();
    grown += v.capacity() == 0;
    v.assign(100, 0.0f);
    ring.Push();
  };
  // Two at a time, a hundred times: as a queue whose consumer keeps up.
  for (int k = 0; k < 100; ++k) {
    put();
    put();
    ring.Pop();
    ring.Pop();
  }
  EXPECT_EQ(grown, 2);
  // Full, then drained and filled again: every slot, and no more.
  while (!ring.full()) put();
  while (!ring.empty()) ring.Pop();
  while (!ring.full()) put();
  EXPECT_EQ(grown, 16);
}

TEST(ReuseRingTest, AnUnpushedSlotIsNotAnElement) {
  ReuseRing<int, 2> ring;
  ring.Next() = 7;  // filled, then given up (a failed conversion)
  EXPECT_TRUE(ring.empty());
  ring.Next() = 8;
  ring.Push();
  EXPECT_EQ(ring.Front(), 8);
  EXPECT_EQ(ring.size(), 1u);
}

}  // namespace
}  // namespace cairn
