// The Xsens driver against an emulated MTi on a pseudo-terminal (drivers/testing/emulated_mti.h):
// configuration, decoding, timestamps, and every fault the issue names, with the daemon's side
// (the sink) seeing samples resume after each.

#include "drivers/xsens_imu_driver.h"

#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <thread>

#include <gtest/gtest.h>

#include "drivers/testing/emulated_mti.h"
#include "tests/support/recording_sink.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

using std::chrono::milliseconds;

XsensImuOptions Options(const std::string& link) {
  XsensImuOptions o;
  o.device = link;
  o.rate_hz = 200.0;
  o.timeout = 0.3;
  o.reopen_interval = 0.1;
  return o;
}

size_t CountFaults(testing::RecordingSink& sink, DeviceFaultKind kind) {
  std::lock_guard lock(sink.mutex);
  return static_cast<size_t>(
      std::count_if(sink.faults.begin(), sink.faults.end(), [&](const DeviceFault& f) { return f.kind == kind; }));
}

class XsensImuDriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    link_ = temp_.path() + "/mti";
    auto device = testing::EmulatedMti::Create(link_);
    ASSERT_TRUE(device.ok()) << device.status().ToString();
    device_ = std::move(*device);
  }
  bool WaitForSamples(size_t n) {
    return sink_.WaitFor([&] { return sink_.imu.size() >= n; });
  }
  const testing::ScopedTempDir temp_{"xsens"};
  std::string link_;
  std::unique_ptr<testing::EmulatedMti> device_;
  testing::RecordingSink sink_;
};

TEST_F(XsensImuDriverTest, ConfiguresTheDeviceAndDecodesItsSamples) {
  XsensImuDriver driver(Options(link_), ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForSamples(100));
  driver.Stop();
  EXPECT_EQ(device_->configurations(), 1u);
  EXPECT_EQ(device_->rate_hz(), 200.0);
  // Packet counter, sample time, acceleration and rate of turn at 200 Hz, status word.
  EXPECT_EQ(device_->output_configuration(),
            (std::vector<uint8_t>{0x10, 0x20, 0xFF, 0xFF, 0x10, 0x60, 0xFF, 0xFF, 0x40, 0x20, 0x00, 0xC8, 0x80, 0x20,
                                  0x00, 0xC8, 0xE0, 0x20, 0xFF, 0xFF}));
  std::lock_guard lock(sink_.mutex);
  EXPECT_TRUE(sink_.faults.empty()) << sink_.faults.front().detail;
  std::vector<double> intervals;
  for (size_t i = 0; i < sink_.imu.size(); ++i) {
    const ImuSample& s = sink_.imu[i];
    EXPECT_NEAR(s.accel.x(), 0.01 * static_cast<double>(i), 1e-5);
    EXPECT_NEAR(s.accel.z(), 9.81, 1e-5);
    EXPECT_NEAR(s.gyro.y(), -0.2, 1e-6);
    if (i > 0) {
      EXPECT_GT(s.time, sink_.imu[i - 1].time) << i;
      intervals.push_back((s.time - sink_.imu[i - 1].time).seconds());
    }
  }
  // The device's 5 ms period from its sample time, not the pty's delivery jitter.
  std::nth_element(intervals.begin(), intervals.begin() + intervals.size() / 2, intervals.end());
  EXPECT_NEAR(intervals[intervals.size() / 2], 0.005, 1e-6);
  EXPECT_EQ(driver.counts().samples, sink_.imu.size());
}

TEST_F(XsensImuDriverTest, CorruptBytesAndLostPacketsAreCountedAndTheStreamGoesOn) {
  XsensImuDriver driver(Options(link_), ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForSamples(20));
  std::vector<uint8_t> damaged = XbusFramer::Encode(0x36, std::vector<uint8_t>{0x40, 0x20, 0x0C, 1, 2, 3});
  damaged[6] ^= 0x01;
  damaged.insert(damaged.begin(), {0x00, 0xFA, 0x55});
  device_->SendRaw(damaged);
  const std::vector<uint8_t> truncated = XbusFramer::Encode(0x36, std::vector<uint8_t>{0x40, 0x20, 0x0C, 1, 2, 3});
  device_->SendRaw(truncated);  // a packet shorter than it declares
  device_->SkipPackets(3);
  const size_t before = sink_.imu.size();
  ASSERT_TRUE(WaitForSamples(before + 40));
  driver.Stop();
  EXPECT_GE(CountFaults(sink_, DeviceFaultKind::kCorruptSample), 2u);
  EXPECT_EQ(CountFaults(sink_, DeviceFaultKind::kOverrun), 1u);
  EXPECT_EQ(driver.counts().lost, 3u);
  std::lock_guard lock(sink_.mutex);
  const auto overrun = std::find_if(sink_.faults.begin(), sink_.faults.end(),
                                    [](const DeviceFault& f) { return f.kind == DeviceFaultKind::kOverrun; });
  EXPECT_NE(overrun->detail.find("3 samples lost"), std::string::npos) << overrun->detail;
  EXPECT_EQ(overrun->device, link_);
}

TEST_F(XsensImuDriverTest, SilenceIsATimeoutAndAVanishedDeviceIsReopened) {
  XsensImuDriver driver(Options(link_), ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForSamples(20));
  device_->SetSilent(true);
  ASSERT_TRUE(sink_.WaitFor([&] {
    return std::any_of(sink_.faults.begin(), sink_.faults.end(),
                       [](const DeviceFault& f) { return f.kind == DeviceFaultKind::kTimeout; });
  }));
  device_->SetSilent(false);
  ASSERT_TRUE(WaitForSamples(sink_.imu.size() + 20));

  // Unplugged: the port hangs up. Plugged in again: a new device node under the same link.
  device_->Vanish();
  ASSERT_TRUE(sink_.WaitFor([&] {
    return std::any_of(sink_.faults.begin(), sink_.faults.end(),
                       [](const DeviceFault& f) { return f.kind == DeviceFaultKind::kDisconnected; });
  }));
  auto again = testing::EmulatedMti::Create(link_);
  ASSERT_TRUE(again.ok()) << again.status().ToString();
  device_ = std::move(*again);
  const size_t before = sink_.imu.size();
  ASSERT_TRUE(WaitForSamples(before + 20));
  driver.Stop();
  EXPECT_EQ(device_->configurations(), 1u);  // the new device was configured too
  EXPECT_EQ(driver.counts().reconnections, 1u);
}

TEST_F(XsensImuDriverTest, AMissingPortOrARefusedConfigurationIsReportedAndRetried) {
  XsensImuOptions o = Options(link_ + "-absent");
  XsensImuDriver absent(o, ImuCalibration{});
  ASSERT_TRUE(absent.Start(&sink_).ok());
  ASSERT_TRUE(sink_.WaitFor([&] { return !sink_.faults.empty(); }));
  absent.Stop();
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_EQ(sink_.faults.front().kind, DeviceFaultKind::kDisconnected);
    EXPECT_NE(sink_.faults.front().detail.find("-absent"), std::string::npos) << sink_.faults.front().detail;
    sink_.faults.clear();
  }

  device_->RefuseConfiguration(true);
  XsensImuDriver driver(Options(link_), ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(sink_.WaitFor([&] { return !sink_.faults.empty(); }));
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_EQ(sink_.faults.front().kind, DeviceFaultKind::kOther);
    EXPECT_NE(sink_.faults.front().detail.find("set output configuration: the device reports error 33"),
              std::string::npos)
        << sink_.faults.front().detail;
  }
  device_->RefuseConfiguration(false);
  ASSERT_TRUE(WaitForSamples(10));  // the next attempt succeeds
  driver.Stop();
  EXPECT_EQ(Options(link_).Validate().ok(), true);
  XsensImuOptions bad = Options(link_);
  bad.baud = 123456;
  EXPECT_FALSE(XsensImuDriver(bad, ImuCalibration{}).Start(&sink_).ok());
}

// A device left with an output this driver cannot use (configure: false): every message is refused
// and counted, but reported once a second, not two hundred times.
TEST_F(XsensImuDriverTest, AnUnusableOutputIsReportedOnceASecond) {
  XsensImuOptions o = Options(link_);
  o.configure = false;
  o.timeout = 60.0;
  device_->SendOrientationOnly(true);
  device_->StartMeasuring();
  XsensImuDriver driver(o, ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(sink_.WaitFor([&] { return sink_.faults.size() >= 2; }));
  driver.Stop();
  std::lock_guard lock(sink_.mutex);
  EXPECT_TRUE(sink_.imu.empty());
  // Over a second of 100 Hz messages, all counted, two or three reports.
  EXPECT_LE(sink_.faults.size(), 3u);
  EXPECT_GT(driver.counts().corrupt, 30u * sink_.faults.size());
  EXPECT_NE(sink_.faults[1].detail.find("messages since the last report"), std::string::npos) << sink_.faults[1].detail;
  EXPECT_NE(sink_.faults[0].detail.find("without acceleration and rate of turn"), std::string::npos)
      << sink_.faults[0].detail;
}

}  // namespace
}  // namespace cairn
