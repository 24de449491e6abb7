// cairnd with `source: live` on the robot profiles' IMUs: the rover's Xsens as an emulated MTi on a
// pseudo-terminal (drivers/testing/emulated_mti.h), the hexacopter's ADIS16407 as a fake IIO
// device (drivers/testing/fake_iio_imu.h). The daemon sets the device up, consumes its samples,
// reports the device vanishing and coming back, and exits cleanly on SIGTERM with the IMU stream
// and the faults in summary.json. The CAN bus and the cameras are absent here, and it says so.

#include <signal.h>
#include <time.h>

#include <chrono>
#include <fstream>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "common/json_value.h"
#include "drivers/testing/emulated_mti.h"
#include "drivers/testing/fake_iio_imu.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

std::string ReadFile(const std::string& path) {
  std::ifstream in(path);
  std::stringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(CairndLiveImuTest, TheRoverProfileRunsLiveOnItsXsensImu) {
  const testing::ScopedTempDir temp("live_imu");
  const std::string dir = temp.path();
  const std::string link = dir + "/mti";
  auto device = testing::EmulatedMti::Create(link);
  ASSERT_TRUE(device.ok()) << device.status().ToString();
  // A second after the daemon configured it (however long its start took), the device is unplugged
  // and plugged in again under the same name.
  std::jthread replug([&](std::stop_token stop) {
    const auto until = [&](double s) {
      const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(s);
      while (!stop.stop_requested() && std::chrono::steady_clock::now() < end)
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
    };
    const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(30);
    while (!stop.stop_requested() && (*device)->samples_sent() < 200 && std::chrono::steady_clock::now() < give_up)
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    (*device)->Vanish();
    until(0.5);
    auto again = testing::EmulatedMti::Create(link);
    if (again.ok()) *device = std::move(*again);
  });
  testing::ProcessOptions po;
  po.signal = SIGTERM;
  po.signal_after = std::chrono::milliseconds(6000);
  po.timeout = std::chrono::milliseconds(60000);
  const testing::ProcessResult r = testing::RunProcess(
      {testing::BinaryDir() + "/daemon/cairnd", "--config", testing::SourceDir() + "/configs/rover.yaml", "--out",
       dir + "/out", "--set", "can.enabled=false", "--set", "imu.xsens.device=" + link, "--set",
       "imu.xsens.rate_hz=200", "--set", "imu.xsens.reopen_interval=0.1", "--set", "live.enabled=false", "--set",
       "recording.enabled=false", "--set", "team.enabled=false", "--set", "daemon.status_interval=0.5"},
      po);
  replug.request_stop();
  replug.join();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  // The profile's cameras are not on this machine: named, retried, and the rest runs.
  EXPECT_NE(r.output.find("192.168.10.11+192.168.10.12: disconnected: 192.168.10.11"), std::string::npos) << r.output;

  const JsonValue summary = JsonValue::Parse(ReadFile(dir + "/out/summary.json"));
  EXPECT_EQ(summary["mode"].string(), "live");
  const JsonValue& imu = summary["streams"]["imu"];
  // A second of 200 Hz samples before the unplugging, more after.
  EXPECT_GT(imu["count"].number(), 200) << ReadFile(dir + "/out/summary.json");
  EXPECT_NEAR(imu["nominal_rate_hz"].number(), 200.0, 1e-9);
  EXPECT_EQ(imu["out_of_order"].number(), 0);
  const JsonValue& faults = summary["faults"];
  EXPECT_EQ(faults["by_device"][link]["disconnected"].number(), 1) << ReadFile(dir + "/out/summary.json");
  EXPECT_EQ(imu["gaps"].number(), 1);  // the half second unplugged
  EXPECT_EQ((*device)->configurations(), 1u);  // the device plugged in again was configured
}

TEST(CairndLiveImuTest, TheHexacopterProfileRunsLiveOnItsIioImu) {
  const testing::ScopedTempDir temp("live_iio");
  const std::string dir = temp.path();
  const std::string sys = dir + "/sys", dev = dir + "/dev";
  auto device = testing::FakeIioImu::Create(sys, dev);
  ASSERT_TRUE(device.ok()) << device.status().ToString();
  // 2 s of records at 200 Hz, written as the kernel would hand them out, then silence.
  std::jthread writer([&](std::stop_token stop) {
    const auto start = std::chrono::steady_clock::now();
    for (int i = 0; i < 400 && !stop.stop_requested(); ++i) {
      std::this_thread::sleep_until(start + std::chrono::microseconds(5000 * i));
      const int16_t accel[3] = {0, 0, 301}, gyro[3] = {1, 2, 3};
      timespec now{};
      clock_gettime(CLOCK_MONOTONIC, &now);
      (*device)->Write(testing::FakeIioImu::Record(accel, gyro, now.tv_sec * 1'000'000'000LL + now.tv_nsec));
    }
  });
  testing::ProcessOptions po;
  po.signal = SIGTERM;
  po.signal_after = std::chrono::milliseconds(4000);
  po.timeout = std::chrono::milliseconds(60000);
  const testing::ProcessResult r = testing::RunProcess(
      {testing::BinaryDir() + "/daemon/cairnd", "--config", testing::SourceDir() + "/configs/hexacopter.yaml", "--out",
       dir + "/out", "--set", "imu.iio.sysfs_root=" + sys, "--set", "imu.iio.dev_root=" + dev, "--set",
       "live.enabled=false", "--set", "recording.enabled=false", "--set", "team.enabled=false"},
      po);
  writer.request_stop();
  writer.join();
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_EQ((*device)->CheckSetup("204.8", "64", false), "");  // set up, and the buffer off again at the end
  const JsonValue summary = JsonValue::Parse(ReadFile(dir + "/out/summary.json"));
  const JsonValue& imu = summary["streams"]["imu"];
  EXPECT_GT(imu["count"].number(), 100) << ReadFile(dir + "/out/summary.json");
  EXPECT_EQ(imu["out_of_order"].number(), 0);
}

}  // namespace
}  // namespace cairn
