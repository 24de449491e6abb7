#pragma once
// `imu:` of a profile whose IMU is an Xsens MTi (MTi-10 series on the rovers) on a serial line.

#include <cstdint>
#include <string>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

struct XsensImuOptions {
  std::string device = "/dev/ttyUSB0";  // the serial port (a udev symlink survives re-plugging)
  int64_t baud = 115200;
  // Configure the output on every (re)connection: packet counter, sample time, acceleration and
  // rate of turn (float32, sensor frame) at `rate_hz`, status word. Off: take what the device sends.
  bool configure = true;
  double rate_hz = 100.0;
  double timeout = 0.5;          // s without a sample: a timeout fault
  double reopen_interval = 1.0;  // s between attempts to open a vanished port
  double command_timeout = 1.0;  // s for the device to acknowledge each configuration message

  void Visit(OptionsVisitor& v) {
    v.Text("device", device);
    v.Integer("baud", baud, 9600, 4000000, "bit/s");
    v.Flag("configure", configure);
    v.Number("rate_hz", rate_hz, 1.0, 2000.0, "Hz");
    v.Number("timeout", timeout, 0.01, 60.0, "s");
    v.Number("reopen_interval", reopen_interval, 0.01, 60.0, "s");
    v.Number("command_timeout", command_timeout, 0.01, 60.0, "s");
  }
  Status Validate() const;
};

}  // namespace cairn
