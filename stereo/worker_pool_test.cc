#include "stereo/worker_pool.h"

#include <atomic>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(WorkerPoolTest, RunsEveryTaskOnceInEveryRound) {
  for (int threads : {1, 2, 4}) {
    WorkerPool pool(threads);
    EXPECT_EQ(pool.threads(), threads);
    for (int round = 0; round < 200; ++round) {
      const int tasks = 1 + round % 7;
      std::vector<std::atomic<int>> hits(tasks);
      pool.ForEach(tasks, [&](int i) { hits[i].fetch_add(1); });
      for (int i = 0; i < tasks; ++i) ASSERT_EQ(hits[i].load(), 1) << "round " << round;
    }
  }
}

}  // namespace
}  // namespace cairn
