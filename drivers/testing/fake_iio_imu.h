#pragma once
// An ADIS16407 as the kernel's IIO driver presents it, for the driver's tests: a sysfs directory
// (name, current_timestamp_clock, sampling_frequency, buffer/, scan_elements/ with the supply,
// accelerometer, gyroscope, temperature and timestamp channels, scales) under a temporary
// sysfs_root, and its character device as a FIFO under dev_root. Records are written in the layout
// the kernel uses when exactly the accelerometer, gyroscope and timestamp are enabled (indices 1-6
// "be:s14/16>>0", index 8 "le:s64/64>>0": 12 bytes, padding to 16, the timestamp, 24 in all),
// worked out by hand here rather than by the code under test.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"

namespace cairn::testing {

class FakeIioImu {
 public:
  static constexpr double kAccelScale = 0.0326;     // m/s^2 per count (3.33 mg)
  static constexpr double kGyroScale = 0.00087266;  // rad/s per count (0.05 deg/s)
  static constexpr size_t kRecordSize = 24;

  // Creates iio:device0 (another device "other" too) under `sysfs_root` and its FIFO under `dev_root`.
  static Expected<std::unique_ptr<FakeIioImu>> Create(const std::string& sysfs_root, const std::string& dev_root);
  ~FakeIioImu();

  // Whether the driver set the device up: exactly the IMU channels on, the monotonic clock, the
  // rate and length, the buffer on (or off again, once the driver stopped). Empty when so, else
  // what differs.
  std::string CheckSetup(const std::string& rate, const std::string& length, bool buffer_on) const;

  // One record: accelerometer and gyroscope counts (14-bit signed), the timestamp in ns.
  static std::vector<uint8_t> Record(const int16_t accel[3], const int16_t gyro[3], int64_t timestamp_ns);
  void Write(std::span<const uint8_t> bytes);
  void Vanish();  // closes the FIFO and removes it and the sysfs directory

  std::string sysfs_dir() const { return dir_; }

 private:
  FakeIioImu() = default;
  std::string dir_, fifo_;
  int fd_ = -1;
};

}  // namespace cairn::testing
