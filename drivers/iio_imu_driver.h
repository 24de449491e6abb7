#pragma once
// An IMU through the Linux IIO subsystem's buffered interface (the hexacopter's ADIS16407 on SPI).
// On every (re)connection the reader thread finds the device by name under sysfs_root, selects the
// monotonic clock for its timestamps, enables exactly the accelerometer, gyroscope and timestamp
// channels, sets the sampling frequency and buffer length, enables the buffer, reads the channel
// layout (iio_scan_layout.h) and scales, then reads records from /dev/iio:deviceN. Each record is
// one ImuSample: accelerations and rates times their scales (the kernel's m/s^2 and rad/s per
// count), stamped with the kernel's timestamp of the data-ready interrupt.
//
// Faults, reported to the sink and never fatal: a device that is not there or vanishes
// (kDisconnected, searched again every reopen_interval), sysfs that cannot be set up (kOther),
// short reads and timestamps that go backwards (kCorruptSample), silence (kTimeout).

#include <atomic>
#include <cstdint>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Core>

#include "common/monotonic_clock.h"
#include "drivers/iio_imu_options.h"
#include "drivers/iio_scan_layout.h"
#include "hal/imu_interface.h"

namespace cairn {

struct IioImuCounts {
  uint64_t samples = 0;
  uint64_t corrupt = 0;
  uint64_t reconnections = 0;
};

class IioImuDriver final : public ImuInterface {
 public:
  IioImuDriver(IioImuOptions options, ImuCalibration calibration);
  ~IioImuDriver() override;

  std::string name() const override { return "iio:" + options_.name; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return false; }
  ImuCalibration calibration() const override { return calibration_; }
  IioImuCounts counts() const { return {samples_.load(), corrupt_.load(), reconnections_.load()}; }

  // The sysfs directory of the device called `name` under `sysfs_root`.
  static Expected<std::string> FindDevice(const std::string& sysfs_root, const std::string& name);

 private:
  // Sets the device up through sysfs and opens its character device.
  Status Open();
  void Close();
  void Run(std::stop_token stop);
  void Fault(DeviceFaultKind kind, const std::string& detail);

  IioImuOptions options_;
  ImuCalibration calibration_;
  SensorSink* sink_ = nullptr;
  MonotonicClock clock_;
  int fd_ = -1;
  std::string sysfs_dir_;
  IioScanLayout layout_;
  int accel_[3] = {-1, -1, -1}, gyro_[3] = {-1, -1, -1}, timestamp_ = -1;
  Eigen::Vector3d accel_scale_ = Eigen::Vector3d::Ones(), gyro_scale_ = Eigen::Vector3d::Ones();
  std::vector<uint8_t> buffer_;
  size_t buffered_ = 0;  // bytes of a partial record at the start of buffer_
  int64_t last_timestamp_ = 0;
  std::atomic<uint64_t> samples_{0}, corrupt_{0}, reconnections_{0};
  std::jthread thread_;
};

}  // namespace cairn
