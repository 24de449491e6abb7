#pragma once
// A local east-north-up frame at a datum on the WGS84 ellipsoid: where the robots of a team place
// geodetic positions (GNSS fixes) in one Cartesian frame. The conversions go through Earth-centred
// Earth-fixed (ECEF) coordinates and are exact, so the frame stays right far from its datum (a
// flat-earth approximation is off by decimetres a few kilometres out).

#include <Eigen/Core>

namespace cairn {

struct GeodeticPoint {
  double latitude = 0.0;   // rad
  double longitude = 0.0;  // rad
  double height = 0.0;     // m above the WGS84 ellipsoid
};

class LocalTangentPlane {
 public:
  explicit LocalTangentPlane(const GeodeticPoint& datum);

  const GeodeticPoint& datum() const { return datum_; }
  // m along the datum's east, north and up.
  Eigen::Vector3d ToEnu(const GeodeticPoint& p) const;
  // Longitude in (-pi, pi]; at a pole it is 0.
  GeodeticPoint ToGeodetic(const Eigen::Vector3d& enu) const;
  // The rotation of ENU axes at `p` into the datum's ENU axes (for covariances given at p).
  Eigen::Matrix3d R_datum_local(const GeodeticPoint& p) const;

  // WGS84 geodetic <-> ECEF (m). The inverse is below 1 um and 1e-12 rad from 5 km below the
  // ellipsoid to 100 km above it.
  static Eigen::Vector3d ToEcef(const GeodeticPoint& p);
  static GeodeticPoint FromEcef(const Eigen::Vector3d& ecef);
  // Columns: east, north and up at `p` in ECEF.
  static Eigen::Matrix3d R_ecef_enu(const GeodeticPoint& p);

 private:
  GeodeticPoint datum_;
  Eigen::Vector3d ecef_datum_;
  Eigen::Matrix3d R_ecef_datum_;  // the datum's ENU axes in ECEF
};

}  // namespace cairn
