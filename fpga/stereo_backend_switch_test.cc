// Backend selection and fallback: cpu / fpga / auto, a device that is absent at start, and one
// that fails in the middle of a run (one warning, a counter, CPU output from then on).

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fpga/simulated_stereo_device.h"
#include "fpga/stereo_backend_switch.h"
#include "stereo/testing/stereo_test_pair.h"

namespace cairn {
namespace {

// The pair every test here matches.
TestStereoPair SwitchTestPair() { return TestStereoPair::Make(36, 10, 6, 17); }

StereoBackendOptions Backend(StereoBackend b) {
  StereoBackendOptions o;
  o.backend = b;
  o.timeout_ms = 1;
  return o;
}

StereoBackendSwitch::DeviceOpener Absent() {
  return []() -> Expected<std::unique_ptr<StereoDevice>> {
    return NotFoundError("fpga device /dev/uio9 not present");
  };
}

StereoBackendSwitch::DeviceOpener Simulated(SimulatedStereoDevice** handle = nullptr) {
  return [handle]() -> Expected<std::unique_ptr<StereoDevice>> {
    auto d = std::make_unique<SimulatedStereoDevice>();
    if (handle != nullptr) *handle = d.get();
    return std::unique_ptr<StereoDevice>(std::move(d));
  };
}

std::vector<int16_t> Cpu(const TestStereoPair& f) {
  auto m = SgmMatcher::Create(FpgaModeTestOptions());
  StereoMatcherOutput out;
  EXPECT_TRUE(m.ok() && (*m)->Match(f.input(), &out).ok());
  return out.disparity;
}

TEST(StereoBackendSwitchTest, CpuNeverOpensTheDevice) {
  bool opened = false;
  auto s = StereoBackendSwitch::Create(Backend(StereoBackend::kCpu), FpgaModeTestOptions(), [&opened]() {
    opened = true;
    return Expected<std::unique_ptr<StereoDevice>>(NotFoundError("x"));
  });
  ASSERT_TRUE(s.ok());
  EXPECT_FALSE(opened);
  EXPECT_FALSE((*s)->fpga_active());
  const TestStereoPair f = SwitchTestPair();
  StereoMatcherOutput out;
  ASSERT_TRUE((*s)->Match(f.input(), &out).ok());
  EXPECT_EQ((*s)->cpu_frames(), 1u);
  EXPECT_EQ((*s)->fpga_failures(), 0u);
}

TEST(StereoBackendSwitchTest, FpgaAndAutoUseThePresentDeviceWithTheCpuResult) {
  const TestStereoPair f = SwitchTestPair();
  for (StereoBackend b : {StereoBackend::kFpga, StereoBackend::kAuto}) {
    auto s = StereoBackendSwitch::Create(Backend(b), FpgaModeTestOptions(), Simulated());
    ASSERT_TRUE(s.ok()) << s.status().ToString();
    EXPECT_TRUE((*s)->fpga_active());
    EXPECT_EQ((*s)->name(), "fpga");
    StereoMatcherOutput out;
    ASSERT_TRUE((*s)->Match(f.input(), &out).ok());
    EXPECT_EQ((*s)->fpga_frames(), 1u);
    EXPECT_EQ(out.disparity, Cpu(f));
  }
}

TEST(StereoBackendSwitchTest, AbsentDeviceFallsBackWithOneWarningOnlyWhenAskedFor) {
  const TestStereoPair f = SwitchTestPair();
  std::vector<std::string> warnings;
  const auto warn = [&warnings](const std::string& m) { warnings.push_back(m); };
  auto fpga = StereoBackendSwitch::Create(Backend(StereoBackend::kFpga), FpgaModeTestOptions(), Absent(), warn);
  ASSERT_TRUE(fpga.ok());
  EXPECT_FALSE((*fpga)->fpga_active());
  EXPECT_EQ((*fpga)->fpga_failures(), 1u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("not present"), std::string::npos);
  StereoMatcherOutput out;
  ASSERT_TRUE((*fpga)->Match(f.input(), &out).ok());
  EXPECT_EQ(out.disparity, Cpu(f));

  warnings.clear();
  auto automatic =
      StereoBackendSwitch::Create(Backend(StereoBackend::kAuto), FpgaModeTestOptions(), Absent(), warn);
  ASSERT_TRUE(automatic.ok());
  EXPECT_FALSE((*automatic)->fpga_active());
  EXPECT_EQ((*automatic)->fpga_failures(), 0u);
  EXPECT_TRUE(warnings.empty());
  EXPECT_EQ((*automatic)->fpga_status().code(), StatusCode::kNotFound);
}

TEST(StereoBackendSwitchTest, OptionsTheCoreCannotRun) {
  SgmOptions full = FpgaModeTestOptions();
  full.raster_paths = false;
  auto fpga = StereoBackendSwitch::Create(Backend(StereoBackend::kFpga), full, Simulated());
  EXPECT_EQ(fpga.status().code(), StatusCode::kInvalidArgument);
  auto automatic = StereoBackendSwitch::Create(Backend(StereoBackend::kAuto), full, Simulated());
  ASSERT_TRUE(automatic.ok());
  EXPECT_FALSE((*automatic)->fpga_active());
}

TEST(StereoBackendSwitchTest, FailureMidRunSwitchesToTheCpuOnceAndKeepsRunning) {
  const TestStereoPair f = SwitchTestPair();
  const auto golden = Cpu(f);
  std::vector<std::string> warnings;
  SimulatedStereoDevice* dev = nullptr;
  auto s = StereoBackendSwitch::Create(
      Backend(StereoBackend::kFpga), FpgaModeTestOptions(), Simulated(&dev),
      [&warnings](const std::string& m) { warnings.push_back(m); });
  ASSERT_TRUE(s.ok());
  StereoMatcherOutput out;
  ASSERT_TRUE((*s)->Match(f.input(), &out).ok());
  EXPECT_EQ(out.disparity, golden);
  EXPECT_EQ((*s)->fpga_frames(), 1u);
  dev->HangDmaWrites(true);  // the next frame times out
  for (int i = 0; i < 3; ++i) {
    ASSERT_TRUE((*s)->Match(f.input(), &out).ok());
    EXPECT_EQ(out.disparity, golden);
  }
  EXPECT_FALSE((*s)->fpga_active());
  EXPECT_EQ((*s)->fpga_failures(), 1u);
  EXPECT_EQ((*s)->cpu_frames(), 3u);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_EQ((*s)->fpga_status().code(), StatusCode::kTimeout);
}

}  // namespace
}  // namespace cairn
