#pragma once
// `imu.iio:` of a profile: an SPI IMU of the ADIS16400 family (the hexacopter's ADIS16407, thesis
// 7.2) through the kernel's IIO driver: its sysfs directory and its buffered character device.

#include <cstdint>
#include <string>

#include "common/options_visitor.h"

namespace cairn {

struct IioImuOptions {
  std::string name = "adis16407";                 // the device's sysfs `name`
  std::string sysfs_root = "/sys/bus/iio/devices";  // searched for a device of that name
  std::string dev_root = "/dev";                    // where its character device is (iio:deviceN)
  double rate_hz = 204.8;                           // sampling_frequency written at start (0: leave it)
  int64_t buffer_length = 64;                       // samples the kernel buffers
  double timeout = 0.5;                             // s without a sample: a fault
  double reopen_interval = 1.0;                     // s between attempts to find a vanished device

  void Visit(OptionsVisitor& v) {
    v.Text("name", name);
    v.Text("sysfs_root", sysfs_root);
    v.Text("dev_root", dev_root);
    v.Number("rate_hz", rate_hz, 0.0, 10000.0, "Hz");
    v.Integer("buffer_length", buffer_length, 2, 65536, "samples");
    v.Number("timeout", timeout, 0.01, 60.0, "s");
    v.Number("reopen_interval", reopen_interval, 0.01, 60.0, "s");
  }
};

}  // namespace cairn
