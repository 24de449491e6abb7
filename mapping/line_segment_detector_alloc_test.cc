// Proves that line segment detection does not allocate after the first image of a size (the binary
// counts allocations).

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/line_segment_detector.h"
#include "tests/support/counting_allocator.h"

namespace cairn {
namespace {

// Random bright rectangles (rotated, overlapping) on a noisy background: many segments of every
// orientation, and more of them in later images than in the first.
std::vector<uint8_t> LineAllocTestImage(int width, int height, int rectangles, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> ux(0.0, width), uy(0.0, height), size(20.0, 120.0), angle(0.0, M_PI);
  std::normal_distribution<double> noise(0.0, 3.0);
  std::vector<double> gray(static_cast<size_t>(width) * static_cast<size_t>(height), 60.0);
  for (int r = 0; r < rectangles; ++r) {
    const double cx = ux(rng), cy = uy(rng), a = size(rng), b = size(rng), t = angle(rng);
    const double c = std::cos(t), s = std::sin(t), level = 80.0 + 20.0 * (r % 8);
    for (int y = 0; y < height; ++y) {
      for (int x = 0; x < width; ++x) {
        const double lx = c * (x - cx) + s * (y - cy), ly = -s * (x - cx) + c * (y - cy);
        if (std::abs(lx) <= a && std::abs(ly) <= b)
          gray[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)] = level;
      }
    }
  }
  std::vector<uint8_t> img(gray.size());
  for (size_t i = 0; i < img.size(); ++i) {
    img[i] = static_cast<uint8_t>(std::clamp(std::lround(gray[i] + noise(rng)), 0l, 255l));
  }
  return img;
}

TEST(LineSegmentDetectorAllocationTest, HookCountsAllocations) {
  testing::CountingAllocator::Arm();
  // Through a volatile pointer: a new and delete pair the compiler sees whole may be left out.
  int* volatile p = new int(3);
  const long counted = testing::CountingAllocator::Disarm();
  delete p;
  EXPECT_EQ(counted, 1);
}

TEST(LineSegmentDetectorAllocationTest, NoAllocationAfterTheFirstImageOfASize) {
  constexpr int kWidth = 640, kHeight = 320;
  const std::vector<uint8_t> first = LineAllocTestImage(kWidth, kHeight, 3, 1);
  LineSegmentOptions options;
  options.min_length_px = 20.0;
  LineSegmentDetector detector(options);
  std::vector<ImageLineSegment> segments;
  LineSegmentDetector::Stats stats;
  ASSERT_TRUE(detector.Detect(first.data(), kWidth, kHeight, kWidth, &segments, &stats));
  const int first_segments = stats.segments;
  int most = 0;
  for (unsigned seed = 2; seed < 6; ++seed) {
    const std::vector<uint8_t> img = LineAllocTestImage(kWidth, kHeight, 40, seed);
    testing::CountingAllocator::Arm();
    const bool ok = detector.Detect(img.data(), kWidth, kHeight, kWidth, &segments, &stats);
    const long counted = testing::CountingAllocator::Disarm();
    ASSERT_TRUE(ok);
    EXPECT_EQ(counted, 0) << "image " << seed;
    most = std::max(most, stats.segments);
  }
  // The later images had far more to hold than the first.
  EXPECT_GT(most, 4 * first_segments);
  EXPECT_EQ(static_cast<int>(segments.size()),
            std::min(stats.segments, static_cast<int>(options.max_segments)));
}

}  // namespace
}  // namespace cairn
