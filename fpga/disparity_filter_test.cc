#include "fpga/disparity_filter.h"

#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "fpga/stereo_matcher_interface.h"

namespace cairn {
namespace {

// The general rule, pixel by pixel.
int16_t ReferenceMedian(const std::vector<int16_t>& in, int w, int h, int x, int y) {
  std::vector<int16_t> v;
  for (int yy = std::max(0, y - 1); yy <= std::min(h - 1, y + 1); ++yy) {
    for (int xx = std::max(0, x - 1); xx <= std::min(w - 1, x + 1); ++xx) {
      if (in[yy * w + xx] != kInvalidDisparity) v.push_back(in[yy * w + xx]);
    }
  }
  std::sort(v.begin(), v.end());
  return v[(v.size() - 1) / 2];
}

TEST(DisparityFilterTest, MedianMatchesTheDefinitionWithInvalidPixels) {
  const int w = 37, h = 11;
  std::mt19937 rng(5);
  std::vector<int16_t> in(w * h), out(w * h);
  for (auto& d : in) d = rng() % 7 == 0 ? kInvalidDisparity : static_cast<int16_t>(rng() % 2000 - 500);
  DisparityFilter::Median3x3(in.data(), out.data(), w, h, 0, h);
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      const int16_t expected =
          in[y * w + x] == kInvalidDisparity ? kInvalidDisparity : ReferenceMedian(in, w, h, x, y);
      ASSERT_EQ(out[y * w + x], expected) << x << "," << y;
    }
  }
}

TEST(DisparityFilterTest, RemovesOnlySmallRegions) {
  const int w = 10, h = 10;
  std::vector<int16_t> d(w * h, 160);
  d[3 * w + 3] = 800;  // a 2-pixel speckle
  d[3 * w + 4] = 810;
  DisparityFilter f;
  f.RemoveSpeckles(d.data(), w, h, 5, 32);
  EXPECT_EQ(d[3 * w + 3], kInvalidDisparity);
  EXPECT_EQ(d[3 * w + 4], kInvalidDisparity);
  EXPECT_EQ(d[0], 160);
  EXPECT_EQ(std::count(d.begin(), d.end(), 160), w * h - 2);
}

TEST(DisparityFilterTest, FillsHolesFromTheFartherSide) {
  const int16_t i = kInvalidDisparity;
  std::vector<int16_t> row = {i, 50, i, i, 80, i};
  DisparityFilter::FillHolesRow(row.data(), 6);
  EXPECT_EQ(row, (std::vector<int16_t>{50, 50, 50, 50, 80, 80}));
  std::vector<int16_t> empty = {i, i};
  DisparityFilter::FillHolesRow(empty.data(), 2);
  EXPECT_EQ(empty[0], i);
}

}  // namespace
}  // namespace cairn
