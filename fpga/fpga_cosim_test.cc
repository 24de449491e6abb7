// Whole-frame cosimulation: the Verilator model of the SGM offload, driven by the host driver
// through the simulated board, against the golden model's raster_paths mode, pixel for pixel.

#include <algorithm>
#include <filesystem>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <opencv2/core.hpp>

#include "fpga/fpga_stereo_matcher.h"
#include "fpga/simulated_stereo_device.h"
#include "stereo/sgm_matcher.h"
#include "stereo/stereo_image_io.h"
#include "stereo/testing/stereo_test_pair.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

SgmOptions FpgaMode(int disparities) {
  SgmOptions o;
  o.raster_paths = true;
  o.num_disparities = disparities;
  o.threads = 1;
  return o;
}

StereoMatcherOutput Golden(SgmOptions o, const StereoMatcherInput& in) {
  o.backend = SgmBackend::kScalar;
  auto m = SgmMatcher::Create(o);
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  StereoMatcherOutput out;
  if (m.ok()) {
    EXPECT_TRUE((*m)->Match(in, &out).ok());
  }
  return out;
}

StereoMatcherOutput Cosim(const SgmOptions& o, const StereoMatcherInput& in,
                          uint32_t* cycles = nullptr) {
  auto m = FpgaStereoMatcher::Create(o, std::make_unique<SimulatedStereoDevice>(),
                                     std::chrono::seconds(10));
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  StereoMatcherOutput out;
  if (!m.ok()) return out;
  const Status s = (*m)->Match(in, &out);
  EXPECT_TRUE(s.ok()) << s.ToString();
  if (cycles != nullptr) *cycles = (*m)->last_frame_cycles();
  return out;
}

int CountValid(const std::vector<int16_t>& d) {
  return static_cast<int>(std::count_if(d.begin(), d.end(),
                                        [](int16_t v) { return v != kInvalidDisparity; }));
}

// Index of the first differing pixel, for readable failures.
std::string FirstDifference(const StereoMatcherOutput& a, const StereoMatcherOutput& b) {
  for (size_t i = 0; i < a.disparity.size() && i < b.disparity.size(); ++i) {
    if (a.disparity[i] != b.disparity[i]) {
      return "first difference at x " + std::to_string(i % a.width) + " y " +
             std::to_string(i / a.width) + ": golden " + std::to_string(a.disparity[i]) +
             " rtl " + std::to_string(b.disparity[i]);
    }
  }
  return "sizes " + std::to_string(a.disparity.size()) + " vs " + std::to_string(b.disparity.size());
}

TEST(FpgaCosimTest, RawDisparityOfSyntheticFramesEqualsGolden) {
  struct Case {
    int w, h, d, shift;
    bool lr, subpixel;
    int uniqueness, p1, p2;
  };
  // Widths below and above the disparity count, not multiples of 8; one group (d = 32) and
  // several.
  const Case cases[] = {{40, 14, 32, 5, true, true, 5, 6, 40},
                        {67, 11, 64, 9, true, true, 10, 8, 60},
                        {150, 9, 128, 20, true, false, 0, 4, 20},
                        {33, 8, 96, 2, false, true, 25, 10, 100}};
  uint32_t seed = 3;
  for (const Case& c : cases) {
    const auto p = TestStereoPair::Make(c.w, c.h, c.shift, seed++, 24, 3);
    SgmOptions o = FpgaMode(c.d);
    o.lr_check = c.lr;
    o.subpixel = c.subpixel;
    o.uniqueness_percent = c.uniqueness;
    o.p1 = c.p1;
    o.p2 = c.p2;
    o.median = false;  // the device's own output, before the host's post-filters
    o.speckle_max_size = 0;
    const auto golden = Golden(o, p.input());
    const auto rtl = Cosim(o, p.input());
    EXPECT_EQ(golden.disparity, rtl.disparity)
        << c.w << "x" << c.h << " d " << c.d << ": " << FirstDifference(golden, rtl);
    EXPECT_GT(CountValid(golden.disparity), c.w * c.h / 10);
  }
}

TEST(FpgaCosimTest, FilteredOutputEqualsGoldenAndReusesTheDevice) {
  const auto a = TestStereoPair::Make(48, 16, 6, 21, 24, 3);
  const auto b = TestStereoPair::Make(48, 16, 11, 22, 24, 3);
  const SgmOptions o = FpgaMode(32);  // median and speckle filter on, as configured by default
  auto m = FpgaStereoMatcher::Create(o, std::make_unique<SimulatedStereoDevice>());
  ASSERT_TRUE(m.ok()) << m.status().ToString();
  StereoMatcherOutput out;
  for (const TestStereoPair* p : {&a, &b, &a}) {
    ASSERT_TRUE((*m)->Match(p->input(), &out).ok());
    const auto golden = Golden(o, p->input());
    EXPECT_EQ(golden.disparity, out.disparity) << FirstDifference(golden, out);
  }
}

TEST(FpgaCosimTest, MiddleburyCropsEqualGolden) {
  struct Crop {
    const char* folder;
    const char* left;
    const char* right;
    cv::Rect roi;
    int d;
  };
  const Crop crops[] = {
      {"middlebury2003-cones", "im2.png", "im6.png", cv::Rect(150, 140, 131, 36), 64},
      {"middlebury2014q-motorcycle", "im0.png", "im1.png", cv::Rect(300, 250, 180, 24), 128}};
  for (const Crop& c : crops) {
    const std::string dir = testing::DataDir() + "/stereo/" + c.folder;
    CAIRN_REQUIRE_PATH(dir + "/" + c.left);
    auto pair = LoadGrayPair(dir + "/" + c.left, dir + "/" + c.right);
    ASSERT_TRUE(pair.ok()) << pair.status().ToString();
    const cv::Mat l = pair->left(c.roi), r = pair->right(c.roi);
    StereoMatcherInput in;  // a crop: the stride is the full image's
    in.left = l.data;
    in.right = r.data;
    in.width = l.cols;
    in.height = l.rows;
    in.stride = static_cast<int>(l.step[0]);
    SgmOptions o = FpgaMode(c.d);
    o.median = false;
    o.speckle_max_size = 0;
    const auto golden = Golden(o, in);
    uint32_t cycles = 0;
    const auto rtl = Cosim(o, in, &cycles);
    EXPECT_EQ(golden.disparity, rtl.disparity) << c.folder << ": " << FirstDifference(golden, rtl);
    EXPECT_GT(CountValid(golden.disparity), l.cols * l.rows / 3) << c.folder;
    EXPECT_GT(cycles, 0u);
  }
}

}  // namespace
}  // namespace cairn
