// RTL unit benches: the combinational blocks of fpga/rtl (built by Verilator into
// SgmUnitBenchModel) against the golden model's functions on random inputs.

#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fpga/cosim/sgm_unit_bench_model.h"
#include "stereo/sgm_kernels.h"
#include "stereo/stereo_matcher_interface.h"

namespace cairn {
namespace {

constexpr int kLanes = SgmUnitBenchModel::kLanes;

TEST(SgmRtlUnitsTest, CensusEqualsGolden) {
  SgmUnitBenchModel rtl;
  std::mt19937 rng(1);
  for (int t = 0; t < 2000; ++t) {
    uint8_t win[25];
    // Few grey levels: equal pairs (bit 0) must be as common as ordered ones.
    const uint32_t levels = t % 2 == 0 ? 4 : 256;
    for (auto& v : win) v = static_cast<uint8_t>(rng() % levels);
    uint32_t golden = 0;
    ScalarSgmKernels().census(win + 12, 5, 1, 5, 5, &golden);
    ASSERT_EQ(golden, rtl.Census(win)) << "trial " << t;
  }
}

TEST(SgmRtlUnitsTest, CostEqualsGolden) {
  SgmUnitBenchModel rtl;
  std::mt19937 rng(2);
  // The golden cost kernel on a row: right census reversed into byte planes, border costs for
  // candidates left of the image (sgm_kernels.h).
  const int w = 80, d = kLanes, bits = 12;
  SgmRowGeometry g;
  g.width = w;
  g.disparities = d;
  g.block = d + kPathTail;
  g.rev_base = w - 1;
  const int n_rev = g.rev_base + d, plane_stride = n_rev + 64;
  std::vector<uint32_t> left(w), right(w);
  for (int trial = 0; trial < 20; ++trial) {
    for (int x = 0; x < w; ++x) {
      left[x] = rng() & 0xFFF;
      right[x] = trial % 2 == 0 ? rng() & 0xFFF : left[std::min(w - 1, x + 3)] ^ (rng() & 0x11);
    }
    std::vector<uint8_t> planes(2 * static_cast<size_t>(plane_stride), 0), border(n_rev, 0);
    for (int i = 0; i < n_rev; ++i) {
      const int xr = w - 1 - i;
      const bool inside = xr >= 0;
      planes[i] = inside ? static_cast<uint8_t>(right[xr]) : 0;
      planes[plane_stride + i] = inside ? static_cast<uint8_t>(right[xr] >> 8) : 0;
      border[i] = inside ? 0 : bits;
    }
    std::vector<uint8_t> golden(static_cast<size_t>(w) * d);
    ScalarSgmKernels().cost(left.data(), planes.data(), plane_stride, 2, border.data(), g,
                            golden.data());
    for (int x = 0; x < w; ++x) {
      uint32_t lanes[kLanes];
      uint32_t outside = 0;
      for (int k = 0; k < kLanes; ++k) {
        lanes[k] = x - k >= 0 ? right[x - k] : 0;
        if (x - k < 0) outside |= 1u << k;
      }
      uint8_t cost[kLanes];
      rtl.Cost(left[x], lanes, outside, cost);
      for (int k = 0; k < kLanes; ++k) {
        ASSERT_EQ(golden[static_cast<size_t>(x) * d + k], cost[k]) << "x " << x << " k " << k;
      }
    }
  }
}

TEST(SgmRtlUnitsTest, AggregationStepEqualsGoldenOverSeveralGroups) {
  SgmUnitBenchModel rtl;
  std::mt19937 rng(3);
  const int groups = 3, d = groups * kLanes;
  for (int t = 0; t < 500; ++t) {
    // prev with sentinels beside the range, as the golden kernels lay it out.
    std::vector<uint8_t> prev_block(static_cast<size_t>(d) + 2, kPathSentinel);
    uint8_t* prev = prev_block.data() + 1;
    std::vector<uint8_t> cost(d), golden(d), out(d);
    const int spread = t % 3 == 0 ? 8 : 120;
    for (int k = 0; k < d; ++k) {
      prev[k] = static_cast<uint8_t>(rng() % spread + (t % 5 == 0 ? 100 : 0));
      cost[k] = static_cast<uint8_t>(rng() % 13);
    }
    const uint8_t min_prev = *std::min_element(prev, prev + d);
    const uint8_t p1 = static_cast<uint8_t>(1 + rng() % 20);
    const uint8_t p2 = static_cast<uint8_t>(p1 + 1 + rng() % 100);
    const uint8_t golden_min = SgmPathStep(cost.data(), prev, min_prev, p1, p2, d, golden.data());
    uint8_t rtl_min = 0xFF;
    for (int g = 0; g < groups; ++g) {
      const int k0 = g * kLanes;
      rtl_min = std::min(rtl_min, rtl.PathStep(cost.data() + k0, prev + k0, prev[k0 - 1],
                                               prev[k0 + kLanes], min_prev, p1, p2,
                                               out.data() + k0));
    }
    ASSERT_EQ(golden, out) << "trial " << t;
    ASSERT_EQ(golden_min, rtl_min) << "trial " << t;
  }
}

TEST(SgmRtlUnitsTest, SubpixelEqualsGolden) {
  SgmUnitBenchModel rtl;
  std::mt19937 rng(4);
  for (int t = 0; t < 20000; ++t) {
    // Sums of four 8-bit paths; the winner is the smallest.
    const int at = static_cast<int>(rng() % 1021);
    const int range = t % 4 == 0 ? 3 : 1021 - at;
    const int below = at + static_cast<int>(rng() % (range + 1));
    const int above = at + static_cast<int>(rng() % (range + 1));
    ASSERT_EQ(SgmSubpixelOffset(below, at, above), rtl.Subpixel(below, at, above))
        << below << " " << at << " " << above;
  }
}

TEST(SgmRtlUnitsTest, LeftRightCheckEqualsGolden) {
  SgmUnitBenchModel rtl;
  std::mt19937 rng(5);
  for (int t = 0; t < 20000; ++t) {
    const int x = static_cast<int>(rng() % 300);
    const int k = static_cast<int>(rng() % 128);
    const int kr = t % 3 == 0 ? k + static_cast<int>(rng() % 5) - 2 : static_cast<int>(rng() % 128);
    const int right_k = std::clamp(kr, 0, 127);
    const bool unique = rng() % 4 != 0;
    const bool lr = rng() % 5 != 0;
    const int max_diff = static_cast<int>(rng() % 4);
    const int value = k * kDisparityScale + static_cast<int>(rng() % 17) - 8;
    // FinishRow's rules (min_disparity 0): not unique, matched left of the right image, or
    // inconsistent with the right winner -> invalid.
    const bool valid = unique && x - k >= 0 && (!lr || SgmLeftRightConsistent(k, right_k, max_diff));
    const int16_t golden = valid ? static_cast<int16_t>(value) : kInvalidDisparity;
    ASSERT_EQ(golden, rtl.LrCheck(x, unique, k, value & 0xFFFF, right_k, lr, max_diff))
        << "x " << x << " k " << k << " kr " << right_k;
  }
}

}  // namespace
}  // namespace cairn
