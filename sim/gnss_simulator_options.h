#pragma once
// `sim.gnss`: a GNSS receiver on the simulated robot (GnssSimulator). The defaults are a
// single-frequency code receiver under open sky: its errors are mostly correlated over a minute or
// so (ionosphere, multipath, satellite geometry), with a smaller part that changes from fix to fix.

#include "common/options_visitor.h"

namespace cairn {

struct GnssSimulatorOptions {
  bool enabled = false;
  double rate_hz = 1.0;
  // White noise of each fix, per axis (east and north; up).
  double sigma_horizontal = 1.5;  // m
  double sigma_vertical = 3.0;    // m
  // First-order Gauss-Markov bias on each of east, north and up: its steady-state sigma and its
  // correlation time.
  double bias_sigma = 1.0;           // m
  double bias_time_constant = 60.0;  // s
  // Outages (no fixes): they start at this rate and last an exponentially distributed time.
  double outage_rate = 0.001;          // 1/s
  double outage_mean_duration = 10.0;  // s
  double latency = 0.1;                // s from the measurement to its publication
  // The antenna in the body frame.
  double antenna_x = 0.0, antenna_y = 0.0, antenna_z = 0.0;  // m
  // The geodetic position of the world frame's origin (world x east, y north, z up). By default
  // near the Piano del Lago, an analogue site on Mt Etna.
  double origin_latitude = 37.72;   // deg
  double origin_longitude = 14.99;  // deg
  double origin_height = 2650.0;    // m above the WGS84 ellipsoid

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("rate_hz", rate_hz, 0.1, 100.0, "Hz");
    v.Number("sigma_horizontal", sigma_horizontal, 0.0, 100.0, "m");
    v.Number("sigma_vertical", sigma_vertical, 0.0, 100.0, "m");
    v.Number("bias_sigma", bias_sigma, 0.0, 100.0, "m");
    v.Number("bias_time_constant", bias_time_constant, 0.1, 86400.0, "s");
    v.Number("outage_rate", outage_rate, 0.0, 1.0, "1/s");
    v.Number("outage_mean_duration", outage_mean_duration, 0.1, 3600.0, "s");
    v.Number("latency", latency, 0.0, 5.0, "s");
    v.Number("antenna_x", antenna_x, -10.0, 10.0, "m");
    v.Number("antenna_y", antenna_y, -10.0, 10.0, "m");
    v.Number("antenna_z", antenna_z, -10.0, 10.0, "m");
    v.Number("origin_latitude", origin_latitude, -90.0, 90.0, "deg");
    v.Number("origin_longitude", origin_longitude, -180.0, 180.0, "deg");
    v.Number("origin_height", origin_height, -1000.0, 10000.0, "m");
  }
};

}  // namespace cairn
