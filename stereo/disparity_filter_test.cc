#include "stereo/disparity_filter.h"

#include <algorithm>
#include <cstdlib>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include <gtest/gtest.h>

#include "stereo/stereo_matcher_interface.h"
#include "stereo/worker_pool.h"

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

void MedianCase(int w, int h);

TEST(DisparityFilterTest, MedianMatchesTheDefinitionWithInvalidPixels) {
  for (const auto& [w, h] : {std::pair{37, 11}, std::pair{203, 9}, std::pair{3, 5}}) {
    SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h));
    MedianCase(w, h);
  }
}

void MedianCase(int w, int h) {
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

// The rule, plainly: flood fill every region, clear it when it is small.
void ReferenceSpeckles(std::vector<int16_t>& d, int w, int h, int max_size, int max_diff) {
  std::vector<uint8_t> seen(d.size(), 0);
  std::vector<int> stack, region;
  for (int start = 0; start < w * h; ++start) {
    if (seen[start] || d[start] == kInvalidDisparity) continue;
    stack = {start};
    region.clear();
    seen[start] = 1;
    while (!stack.empty()) {
      const int p = stack.back();
      stack.pop_back();
      region.push_back(p);
      const int px = p % w, py = p / w;
      const int nx[4] = {px - 1, px + 1, px, px}, ny[4] = {py, py, py - 1, py + 1};
      for (int i = 0; i < 4; ++i) {
        if (nx[i] < 0 || nx[i] >= w || ny[i] < 0 || ny[i] >= h) continue;
        const int q = ny[i] * w + nx[i];
        if (seen[q] || d[q] == kInvalidDisparity || std::abs(d[q] - d[p]) > max_diff) continue;
        seen[q] = 1;
        stack.push_back(q);
      }
    }
    if (static_cast<int>(region.size()) < max_size) {
      for (int p : region) d[p] = kInvalidDisparity;
    }
  }
}

// Row bands on threads, joined at the band borders, remove exactly what one flood fill removes.
TEST(DisparityFilterTest, SpecklesOnThreadsMatchOneThread) {
  const int w = 83, h = 131;
  std::mt19937 rng(11);
  for (int trial = 0; trial < 6; ++trial) {
    // Blocky disparities with noise and holes: regions of every size, many crossing band borders.
    std::vector<int16_t> d(static_cast<size_t>(w) * h);
    const int cell = 2 + trial;
    std::vector<int16_t> cells(static_cast<size_t>((w / cell + 1) * (h / cell + 1)));
    for (auto& c : cells) c = static_cast<int16_t>(rng() % 6 * 40);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        int16_t v = static_cast<int16_t>(cells[static_cast<size_t>((y / cell) * (w / cell + 1) + x / cell)] +
                                         rng() % 9);
        if (rng() % 13 == 0) v = kInvalidDisparity;
        if (trial % 2 == 1 && x % 17 == 5) v = static_cast<int16_t>(500 + y % 3);  // long thin regions
        d[static_cast<size_t>(y) * w + x] = v;
      }
    }
    std::vector<int16_t> reference = d;
    ReferenceSpeckles(reference, w, h, 10 + 15 * trial, 8);
    std::vector<int16_t> single = d;
    DisparityFilter one;
    one.RemoveSpeckles(single.data(), w, h, 10 + 15 * trial, 8);
    EXPECT_EQ(single, reference) << "trial " << trial << ", no pool";
    for (int threads : {2, 3}) {
      WorkerPool pool(threads);
      DisparityFilter banded;
      std::vector<int16_t> out = d;
      banded.RemoveSpeckles(out.data(), w, h, 10 + 15 * trial, 8, &pool);
      EXPECT_EQ(out, reference) << "trial " << trial << ", " << threads << " threads";
      out = d;  // buffers reused
      banded.RemoveSpeckles(out.data(), w, h, 10 + 15 * trial, 8, &pool);
      EXPECT_EQ(out, reference) << "trial " << trial << ", again";
    }
    EXPECT_NE(reference, d);
  }
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
