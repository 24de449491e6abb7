#pragma once

#include <cstdint>

#include <Eigen/Core>

#include "common/timestamp.h"

namespace cairn {

// Receiver solution type, as NMEA GGA reports it (field 6).
enum class GnssQuality : uint8_t {
  kNone = 0,
  kAutonomous = 1,
  kDifferential = 2,
  kRtkFixed = 4,
  kRtkFloat = 5,
};

// One position fix of a GNSS receiver's antenna. Geodetic on WGS84 so that every robot of a team
// can place it in one local tangent plane; the covariance is the receiver's reported accuracy.
struct GnssFix {
  Timestamp time;          // when the receiver measured, on the robot's monotonic clock
  double latitude = 0.0;   // rad
  double longitude = 0.0;  // rad
  double height = 0.0;     // m above the WGS84 ellipsoid
  Eigen::Matrix3d covariance = Eigen::Matrix3d::Identity();  // m^2, axes east, north, up
  GnssQuality quality = GnssQuality::kNone;
  int satellites = 0;
};

}  // namespace cairn
