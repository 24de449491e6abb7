// Runs under ThreadSanitizer (label concurrency): the two sweeps of SgmMatcher share the sum
// volume and the worker pool; the result must not depend on the thread count.
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "stereo/sgm_matcher.h"

namespace cairn {
namespace {

TEST(SgmMatcherThreadsTest, TwoSweepsOnThreadsGiveTheSingleThreadResult) {
  const int w = 90, h = 40;
  std::mt19937 rng(3);
  std::vector<uint8_t> l(static_cast<size_t>(w) * h), r(l.size());
  for (auto& v : l) v = static_cast<uint8_t>(rng());
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) r[static_cast<size_t>(y) * w + x] = l[static_cast<size_t>(y) * w + std::min(w - 1, x + 7)];
  }
  StereoMatcherInput in;
  in.left = l.data();
  in.right = r.data();
  in.width = w;
  in.height = h;
  in.stride = w;
  std::vector<int16_t> reference;
  for (int threads : {1, 2, 4}) {
    SgmOptions o;
    o.num_disparities = 16;
    o.paths = 8;
    o.threads = threads;
    auto m = SgmMatcher::Create(o);
    ASSERT_TRUE(m.ok());
    StereoMatcherOutput out;
    for (int frame = 0; frame < 3; ++frame) {
      ASSERT_TRUE((*m)->Match(in, &out).ok());
      if (reference.empty()) reference = out.disparity;
      EXPECT_EQ(out.disparity, reference) << threads << " threads, frame " << frame;
    }
  }
}

}  // namespace
}  // namespace cairn
