#pragma once
// `gnss:` of a profile whose GNSS receiver speaks NMEA 0183 on a serial line: GGA for the position,
// GST for its accuracy (nmea_parser.h).

#include <cstdint>
#include <string>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

struct NmeaGnssOptions {
  std::string device = "/dev/ttyACM0";  // the serial port (a udev symlink survives re-plugging)
  int64_t baud = 115200;                // a USB (CDC-ACM) receiver ignores it, a UART needs it
  // Each fix's covariance from the GST sentence of its epoch (the receiver must be set to send
  // GST, or each fix waits for the next epoch). Off, or when an epoch's GST does not come, from
  // HDOP: sigma east = sigma north = HDOP * uere, sigma up = vertical_factor * that.
  bool use_gst = true;
  double uere = 3.0;             // m, horizontal sigma per axis at HDOP 1
  double vertical_factor = 1.5;  // vertical over horizontal sigma of the HDOP model
  // s from the receiver's measurement to the end of its GGA line on the serial port (its
  // computation and output delay); subtracted from the arrival time to stamp the fix.
  double latency = 0.0;
  double timeout = 2.0;          // s without a fix: a timeout fault
  double reopen_interval = 1.0;  // s between attempts to open a vanished port

  void Visit(OptionsVisitor& v) {
    v.Text("device", device);
    v.Integer("baud", baud, 9600, 4000000, "bit/s");
    v.Flag("use_gst", use_gst);
    v.Number("uere", uere, 0.01, 100.0, "m");
    v.Number("vertical_factor", vertical_factor, 0.1, 10.0, "");
    v.Number("latency", latency, 0.0, 1.0, "s");
    v.Number("timeout", timeout, 0.01, 60.0, "s");
    v.Number("reopen_interval", reopen_interval, 0.01, 60.0, "s");
  }
  Status Validate() const;
};

}  // namespace cairn
