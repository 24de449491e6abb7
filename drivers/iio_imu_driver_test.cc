// The IIO driver against a fake ADIS16407 (drivers/testing/fake_iio_imu.h): sysfs set-up, decoding
// and scaling, records split across reads, timestamps that go backwards, a device that is absent
// at start and one that vanishes and comes back.

#include "drivers/iio_imu_driver.h"

#include <algorithm>
#include <filesystem>

#include <gtest/gtest.h>

#include "drivers/testing/fake_iio_imu.h"
#include "tests/support/recording_sink.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

using testing::FakeIioImu;

class IioImuDriverTest : public ::testing::Test {
 protected:
  void SetUp() override {
    const std::string root = temp_.path();
    options_.sysfs_root = root + "/sys";
    options_.dev_root = root + "/dev";
    options_.rate_hz = 204.8;
    options_.buffer_length = 128;
    options_.reopen_interval = 0.05;
    options_.timeout = 0.3;
  }
  void Send(int n, int64_t first_ns) {
    for (int i = 0; i < n; ++i) {
      const int16_t accel[3] = {static_cast<int16_t>(i), -300, 8191};
      const int16_t gyro[3] = {-8192, static_cast<int16_t>(-i), 1};
      device_->Write(FakeIioImu::Record(accel, gyro, first_ns + i * 4'882'812));
    }
  }
  bool WaitFor(size_t samples) {
    return sink_.WaitFor([&] { return sink_.imu.size() >= samples; });
  }
  bool WaitForFault(DeviceFaultKind kind) {
    return sink_.WaitFor([&] {
      return std::any_of(sink_.faults.begin(), sink_.faults.end(), [&](const DeviceFault& f) { return f.kind == kind; });
    });
  }
  const testing::ScopedTempDir temp_{"iio"};
  IioImuOptions options_;
  std::unique_ptr<FakeIioImu> device_;
  testing::RecordingSink sink_;
};

TEST_F(IioImuDriverTest, SetsTheDeviceUpAndScalesItsRecords) {
  auto d = FakeIioImu::Create(options_.sysfs_root, options_.dev_root);
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  device_ = std::move(*d);
  IioImuDriver driver(options_, ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  Send(50, 1'000'000'000);
  // Half a record, then the rest: a pipe need not hand out whole records.
  const int16_t a[3] = {1, 2, 3}, g[3] = {4, 5, 6};
  const std::vector<uint8_t> r = FakeIioImu::Record(a, g, 2'000'000'000);
  device_->Write(std::span<const uint8_t>(r.data(), 10));
  device_->Write(std::span<const uint8_t>(r.data() + 10, r.size() - 10));
  ASSERT_TRUE(WaitFor(51));
  EXPECT_EQ(device_->CheckSetup("204.8", "128", true), "");
  driver.Stop();
  std::lock_guard lock(sink_.mutex);
  EXPECT_TRUE(sink_.faults.empty()) << sink_.faults.front().detail;
  for (int i = 0; i < 50; ++i) {
    const ImuSample& s = sink_.imu[static_cast<size_t>(i)];
    EXPECT_NEAR(s.accel.x(), i * FakeIioImu::kAccelScale, 1e-12);
    EXPECT_NEAR(s.accel.y(), -300 * FakeIioImu::kAccelScale, 1e-12);
    EXPECT_NEAR(s.accel.z(), 8191 * FakeIioImu::kAccelScale, 1e-12);
    EXPECT_NEAR(s.gyro.x(), -8192 * FakeIioImu::kGyroScale, 1e-12);
    EXPECT_NEAR(s.gyro.y(), -i * FakeIioImu::kGyroScale, 1e-12);
    EXPECT_EQ(s.time.nanoseconds(), 1'000'000'000 + i * 4'882'812);
  }
  EXPECT_EQ(sink_.imu[50].time.nanoseconds(), 2'000'000'000);
  EXPECT_NEAR(sink_.imu[50].gyro.z(), 6 * FakeIioImu::kGyroScale, 1e-12);
}

TEST_F(IioImuDriverTest, BackwardTimestampsAreDroppedAndAMissingDeviceIsAwaited) {
  std::filesystem::create_directories(options_.sysfs_root);  // the subsystem, without the device
  IioImuDriver driver(options_, ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kDisconnected));
  {
    std::lock_guard lock(sink_.mutex);
    EXPECT_NE(sink_.faults.front().detail.find("no IIO device named 'adis16407'"), std::string::npos)
        << sink_.faults.front().detail;
  }
  auto d = FakeIioImu::Create(options_.sysfs_root, options_.dev_root);
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  device_ = std::move(*d);
  Send(10, 5'000'000'000);
  Send(1, 4'000'000'000);  // earlier than the last
  Send(10, 6'000'000'000);
  ASSERT_TRUE(WaitFor(20));
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kCorruptSample));
  driver.Stop();
  EXPECT_EQ(driver.counts().corrupt, 1u);
  std::lock_guard lock(sink_.mutex);
  EXPECT_EQ(sink_.imu.size(), 20u);
}

TEST_F(IioImuDriverTest, AVanishedDeviceIsFoundAgain) {
  auto d = FakeIioImu::Create(options_.sysfs_root, options_.dev_root);
  ASSERT_TRUE(d.ok());
  device_ = std::move(*d);
  IioImuDriver driver(options_, ImuCalibration{});
  ASSERT_TRUE(driver.Start(&sink_).ok());
  Send(10, 1'000'000'000);
  ASSERT_TRUE(WaitFor(10));
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kTimeout));  // silence
  device_->Vanish();
  ASSERT_TRUE(WaitForFault(DeviceFaultKind::kDisconnected));
  auto again = FakeIioImu::Create(options_.sysfs_root, options_.dev_root);
  ASSERT_TRUE(again.ok());
  device_ = std::move(*again);
  Send(10, 3'000'000'000);
  ASSERT_TRUE(WaitFor(20));
  EXPECT_EQ(device_->CheckSetup("204.8", "128", true), "");
  driver.Stop();
  EXPECT_EQ(driver.counts().reconnections, 1u);
  EXPECT_EQ(device_->CheckSetup("204.8", "128", false), "");  // the buffer is off again
}

}  // namespace
}  // namespace cairn
