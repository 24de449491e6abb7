#include "fpga/sgm_matcher.h"

#include <random>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

std::vector<uint8_t> RandomImage(int w, int h, uint32_t seed) {
  std::mt19937 rng(seed);
  std::vector<uint8_t> img(static_cast<size_t>(w) * h);
  for (auto& v : img) v = static_cast<uint8_t>(rng() & 0xFF);
  return img;
}

StereoMatcherOutput RunSgm(const SgmOptions& o, const std::vector<uint8_t>& l,
                        const std::vector<uint8_t>& r, int w, int h) {
  auto m = SgmMatcher::Create(o);
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  StereoMatcherInput in;
  in.left = l.data();
  in.right = r.data();
  in.width = w;
  in.height = h;
  in.stride = w;
  StereoMatcherOutput out;
  EXPECT_TRUE((*m)->Match(in, &out).ok());
  return out;
}

TEST(SgmMatcherTest, ScalarEqualsSimdOnRandomImages) {
  const int w = 97, h = 41;
  const auto l = RandomImage(w, h, 1), r = RandomImage(w, h, 2);
  for (int paths : {4, 8}) {
    SgmOptions o;
    o.num_disparities = 32;
    o.paths = paths;
    o.backend = SgmBackend::kScalar;
    const auto a = RunSgm(o, l, r, w, h);
    o.backend = SgmBackend::kSimd;
    const auto b = RunSgm(o, l, r, w, h);
    EXPECT_EQ(a.disparity, b.disparity) << "paths " << paths;
  }
}

}  // namespace
}  // namespace cairn
