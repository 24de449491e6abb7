// Proves that dense stereo on a pair, its depth image and its edges allocate nothing once the
// mapping stage has held as many images of the size as ever wait at once, and that estimates
// never allocate (the binary counts allocations).

#include <algorithm>
#include <cstdint>
#include <memory>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/pipeline/mapping_stage.h"
#include "tests/support/counting_allocator.h"

namespace cairn {
namespace {

constexpr int kAllocWidth = 320, kAllocHeight = 240, kAllocShift = 12;

// Blocks of random grey levels with bright bars (edges for the line extractor); the right image
// is the left one moved by kAllocShift px to the left (disparity kAllocShift), so every pair has
// depth.
struct AllocTestPair {
  std::vector<uint8_t> left, right;
  explicit AllocTestPair(unsigned seed)
      : left(static_cast<size_t>(kAllocWidth) * kAllocHeight), right(left.size()) {
    std::mt19937 rng(seed);
    std::uniform_int_distribution<int> grey(20, 235);
    std::vector<uint8_t> wide(static_cast<size_t>(kAllocWidth + kAllocShift) * kAllocHeight);
    const int w = kAllocWidth + kAllocShift;
    for (int y = 0; y < kAllocHeight; y += 4) {
      for (int x = 0; x < w; x += 4) {
        const auto g = static_cast<uint8_t>(grey(rng));
        for (int dy = 0; dy < 4; ++dy)
          for (int dx = 0; dx < 4 && x + dx < w; ++dx) wide[static_cast<size_t>(y + dy) * w + x + dx] = g;
      }
    }
    for (int y = 40; y < 200; ++y) {
      for (int x = 100 + static_cast<int>(seed % 7); x < 110 + static_cast<int>(seed % 7); ++x)
        wide[static_cast<size_t>(y) * w + x] = 255;
    }
    for (int y = 0; y < kAllocHeight; ++y) {
      std::copy_n(&wide[static_cast<size_t>(y) * w], kAllocWidth,
                  &left[static_cast<size_t>(y) * kAllocWidth]);
      std::copy_n(&wide[static_cast<size_t>(y) * w + kAllocShift], kAllocWidth,
                  &right[static_cast<size_t>(y) * kAllocWidth]);
    }
  }
  RectifiedPair Pair(int64_t k) const {
    RectifiedPair p;
    p.time = Timestamp::FromNanoseconds(k * 50'000'000);
    p.frame_counter = static_cast<uint64_t>(k);
    p.left = Image::GrayView(left.data(), kAllocWidth, kAllocHeight, kAllocWidth);
    p.right = Image::GrayView(right.data(), kAllocWidth, kAllocHeight, kAllocWidth);
    return p;
  }
};

TEST(MappingStageAllocationTest, APairAllocatesNothingOnceTheWaitingSlotsAreGrown) {
  MappingSetup setup;
  setup.robot = "alloc";
  setup.stereo.backend.backend = StereoBackend::kCpu;
  setup.stereo.bidirectional = true;
  setup.stereo.sgm.raster_paths = true;
  setup.stereo.sgm.num_disparities = 64;
  setup.mapping.enabled = true;
  setup.mapping.write_submaps = false;
  setup.mapping.map.lines.enabled = true;
  setup.camera.width = kAllocWidth;
  setup.camera.height = kAllocHeight;
  setup.camera.f = 300.0;
  setup.camera.cx = kAllocWidth / 2.0;
  setup.camera.cy = kAllocHeight / 2.0;
  setup.camera.baseline = 0.12;
  auto stage = MappingStage::Create(setup, nullptr);
  ASSERT_TRUE(stage.ok()) << stage.status().ToString();
  const AllocTestPair a(1), b(2);
  // No estimate comes, so images wait until the oldest are given up: every slot grows.
  int64_t k = 0;
  for (; k < 40; ++k) (*stage)->OnPair((k % 2 == 0 ? a : b).Pair(k));
  ASSERT_EQ((*stage)->report().pairs, 40u);
  ASSERT_GT((*stage)->report().line_sightings, 0u)
      << "the pairs must have edges for this test to hold; detected " << (*stage)->report().line_segments;
  for (; k < 60; ++k) {
    const RectifiedPair pair = (k % 2 == 0 ? a : b).Pair(k);
    FrameEstimate estimate;
    estimate.time = pair.time + Duration::Milliseconds(1);  // no image's: they keep waiting
    testing::CountingAllocator::Arm();
    (*stage)->OnPair(pair);
    (*stage)->OnEstimate(estimate);
    const long counted = testing::CountingAllocator::Disarm();
    EXPECT_EQ(counted, 0) << "pair " << k;
  }
  EXPECT_EQ((*stage)->report().pairs, 60u);
  EXPECT_EQ((*stage)->report().match_failures, 0u);
  EXPECT_EQ((*stage)->report().images_dropped, 60u - 16u);
}

TEST(MappingStageAllocationTest, EstimatesWithoutImagesWaitInABoundedRing) {
  MappingSetup setup;
  setup.mapping.enabled = true;
  setup.mapping.write_submaps = false;
  setup.stereo.sgm.num_disparities = 64;
  setup.camera.width = kAllocWidth;
  setup.camera.height = kAllocHeight;
  setup.camera.f = 300.0;
  setup.camera.baseline = 0.12;
  auto stage = MappingStage::Create(setup, nullptr);
  ASSERT_TRUE(stage.ok()) << stage.status().ToString();
  for (int64_t k = 0; k < 300; ++k) {
    FrameEstimate e;
    e.time = Timestamp::FromNanoseconds(k * 50'000'000);
    testing::CountingAllocator::Arm();
    (*stage)->OnEstimate(e);
    EXPECT_EQ(testing::CountingAllocator::Disarm(), 0) << "estimate " << k;
  }
  EXPECT_EQ((*stage)->report().estimates_dropped, 300u - 256u);
}

}  // namespace
}  // namespace cairn
