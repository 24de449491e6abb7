// The FPGA driver's error paths against the simulated board: absent or foreign devices, options
// the core cannot run, DMA faults, a hung bus (timeout) and removal in the middle of a frame. After
// each recoverable error the device must run the next frame correctly.

#include <memory>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "fpga/fpga_stereo_matcher.h"
#include "fpga/sgm_registers.h"
#include "fpga/simulated_stereo_device.h"
#include "fpga/uio_stereo_device.h"
#include "stereo/sgm_matcher.h"
#include "stereo/testing/stereo_test_pair.h"

namespace cairn {
namespace {

// The pair every test here matches.
TestStereoPair MatcherTestPair() { return TestStereoPair::Make(40, 12, 4, 9); }

std::vector<int16_t> Golden(const TestStereoPair& f) {
  auto m = SgmMatcher::Create(FpgaModeTestOptions());
  StereoMatcherOutput out;
  EXPECT_TRUE(m.ok() && (*m)->Match(f.input(), &out).ok());
  return out.disparity;
}

// A register window that answers with a fixed value everywhere.
class ConstantDevice final : public StereoDevice {
 public:
  explicit ConstantDevice(uint32_t value) : value_(value) {}
  std::string_view name() const override { return "constant"; }
  uint32_t Read32(uint32_t) override { return value_; }
  void Write32(uint32_t, uint32_t) override {}
  Expected<DmaBuffer> AllocateDma(size_t) override { return UnavailableError("no DMA"); }
  void ReleaseDma() override {}
  Status WaitForInterrupt(std::chrono::nanoseconds) override { return TimeoutError("none"); }

 private:
  uint32_t value_;
};

// Creates a matcher on a simulated device and keeps a handle on the device for fault injection.
std::unique_ptr<FpgaStereoMatcher> OnSimulator(SimulatedStereoDevice** device,
                                               std::chrono::nanoseconds timeout) {
  auto dev = std::make_unique<SimulatedStereoDevice>();
  *device = dev.get();
  auto m = FpgaStereoMatcher::Create(FpgaModeTestOptions(), std::move(dev), timeout);
  EXPECT_TRUE(m.ok()) << m.status().ToString();
  return m.ok() ? std::move(*m) : nullptr;
}

TEST(FpgaStereoMatcherTest, AbsentOrForeignDevicesAreReported) {
  auto gone = FpgaStereoMatcher::Create(FpgaModeTestOptions(), std::make_unique<ConstantDevice>(0xFFFFFFFFu));
  EXPECT_EQ(gone.status().code(), StatusCode::kUnavailable) << gone.status().ToString();
  auto other = FpgaStereoMatcher::Create(FpgaModeTestOptions(), std::make_unique<ConstantDevice>(0x12345678u));
  EXPECT_EQ(other.status().code(), StatusCode::kNotFound);
  EXPECT_NE(other.status().message().find("0x12345678"), std::string::npos);
  auto none = FpgaStereoMatcher::Create(FpgaModeTestOptions(), nullptr);
  EXPECT_EQ(none.status().code(), StatusCode::kUnavailable);
  auto uio = UioStereoDevice::Open("/dev/uio-cairn-test-absent");
  EXPECT_FALSE(uio.ok());
  auto not_uio = UioStereoDevice::Open("/dev/null");
  EXPECT_EQ(not_uio.status().code(), StatusCode::kInvalidArgument);
}

TEST(FpgaStereoMatcherTest, RejectsOptionsTheCoreCannotRun) {
  const auto reject = [](SgmOptions o, const char* what) {
    auto m = FpgaStereoMatcher::Create(o, std::make_unique<SimulatedStereoDevice>());
    EXPECT_EQ(m.status().code(), StatusCode::kInvalidArgument) << what;
  };
  SgmOptions o = FpgaModeTestOptions();
  o.raster_paths = false;
  reject(o, "full path set");
  o = FpgaModeTestOptions();
  o.census_width = 9;
  o.census_height = 7;
  reject(o, "9x7 census");
  o = FpgaModeTestOptions();
  o.min_disparity = 4;
  reject(o, "min disparity");
  o = FpgaModeTestOptions();
  o.num_disparities = 48;
  reject(o, "not a multiple of the lanes");
  o.num_disparities = 256;
  reject(o, "more than the core's maximum");
  // Too wide for the core is not the caller's fault (the CPU takes it): OutOfRange.
  auto m = FpgaStereoMatcher::Create(FpgaModeTestOptions(), std::make_unique<SimulatedStereoDevice>());
  ASSERT_TRUE(m.ok());
  std::vector<uint8_t> wide(2000 * 4, 0);
  StereoMatcherInput in;
  in.left = in.right = wide.data();
  in.width = in.stride = 2000;
  in.height = 4;
  StereoMatcherOutput out;
  EXPECT_EQ((*m)->Match(in, &out).code(), StatusCode::kOutOfRange);
}

TEST(FpgaStereoMatcherTest, DmaReadFaultIsReportedAndTheNextFrameWorks) {
  const TestStereoPair f = MatcherTestPair();
  SimulatedStereoDevice* dev = nullptr;
  auto m = OnSimulator(&dev, std::chrono::milliseconds(50));
  ASSERT_NE(m, nullptr);
  StereoMatcherOutput out;
  dev->InjectDmaReadFault();
  const Status s = m->Match(f.input(), &out);
  EXPECT_EQ(s.code(), StatusCode::kInternal) << s.ToString();
  EXPECT_NE(s.message().find("DMA read error"), std::string::npos) << s.message();
  ASSERT_TRUE(m->Match(f.input(), &out).ok());
  EXPECT_EQ(out.disparity, Golden(f));
}

TEST(FpgaStereoMatcherTest, HungBusTimesOutAndAbortRecovers) {
  const TestStereoPair f = MatcherTestPair();
  SimulatedStereoDevice* dev = nullptr;
  auto m = OnSimulator(&dev, std::chrono::microseconds(200));  // 30000 simulated cycles
  ASSERT_NE(m, nullptr);
  StereoMatcherOutput out;
  dev->HangDmaWrites(true);
  const Status s = m->Match(f.input(), &out);
  EXPECT_EQ(s.code(), StatusCode::kTimeout) << s.ToString();
  EXPECT_EQ(dev->Read32(sgm_reg::kStatus) & sgm_reg::kStatusBusy, 0u);  // aborted
  dev->HangDmaWrites(false);
  ASSERT_TRUE(m->Match(f.input(), &out).ok());
  EXPECT_EQ(out.disparity, Golden(f));
}

TEST(FpgaStereoMatcherTest, RemovalMidFrameIsReported) {
  const TestStereoPair f = MatcherTestPair();
  SimulatedStereoDevice* dev = nullptr;
  auto m = OnSimulator(&dev, std::chrono::milliseconds(50));
  ASSERT_NE(m, nullptr);
  StereoMatcherOutput out;
  ASSERT_TRUE(m->Match(f.input(), &out).ok());  // the frame takes ~500 cycles
  dev->RemoveAfterCycles(300);
  const Status s = m->Match(f.input(), &out);
  EXPECT_EQ(s.code(), StatusCode::kUnavailable) << s.ToString();
  EXPECT_NE(s.message().find("removed"), std::string::npos);
  EXPECT_EQ(m->Match(f.input(), &out).code(), StatusCode::kUnavailable);
}

TEST(FpgaStereoMatcherTest, CoreRejectsBadGeometryWithTheConfigFlag) {
  // The hardware's own check, below the driver: a width beyond the core's maximum.
  SimulatedStereoDevice dev;
  dev.Write32(sgm_reg::kWidth, 4000);
  dev.Write32(sgm_reg::kHeight, 10);
  dev.Write32(sgm_reg::kNumDisparities, 32);
  dev.Write32(sgm_reg::kIrqStatus, 3);
  dev.Write32(sgm_reg::kControl, sgm_reg::kControlIrqEnable | sgm_reg::kControlStart);
  ASSERT_TRUE(dev.WaitForInterrupt(std::chrono::microseconds(10)).ok());
  const uint32_t status = dev.Read32(sgm_reg::kStatus);
  EXPECT_TRUE(status & sgm_reg::kStatusConfigError);
  EXPECT_TRUE(status & sgm_reg::kStatusError);
  EXPECT_FALSE(status & sgm_reg::kStatusBusy);
  EXPECT_EQ(dev.Read32(sgm_reg::kIrqStatus), sgm_reg::kIrqError);
  EXPECT_EQ(dev.Read32(sgm_reg::kId), sgm_reg::kIdValue);
}

}  // namespace
}  // namespace cairn
