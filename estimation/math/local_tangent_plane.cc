#include "estimation/math/local_tangent_plane.h"

#include <cmath>
#include <numbers>

namespace cairn {
namespace {

// WGS84 defining constants and the ones derived from them.
constexpr double kLtpA = 6378137.0;                  // m, semi-major axis
constexpr double kLtpF = 1.0 / 298.257223563;        // flattening
constexpr double kLtpB = kLtpA * (1.0 - kLtpF);      // m, semi-minor axis
constexpr double kLtpE2 = kLtpF * (2.0 - kLtpF);     // first eccentricity squared
constexpr double kLtpEp2 = kLtpE2 / (1.0 - kLtpE2);  // second eccentricity squared
constexpr double kLtpPi = std::numbers::pi;

}  // namespace

LocalTangentPlane::LocalTangentPlane(const GeodeticPoint& datum)
    : datum_(datum), ecef_datum_(ToEcef(datum)), R_ecef_datum_(R_ecef_enu(datum)) {}

Eigen::Vector3d LocalTangentPlane::ToEnu(const GeodeticPoint& p) const {
  return R_ecef_datum_.transpose() * (ToEcef(p) - ecef_datum_);
}

GeodeticPoint LocalTangentPlane::ToGeodetic(const Eigen::Vector3d& enu) const {
  return FromEcef(ecef_datum_ + R_ecef_datum_ * enu);
}

Eigen::Matrix3d LocalTangentPlane::R_datum_local(const GeodeticPoint& p) const {
  return R_ecef_datum_.transpose() * R_ecef_enu(p);
}

Eigen::Vector3d LocalTangentPlane::ToEcef(const GeodeticPoint& p) {
  const double s = std::sin(p.latitude), c = std::cos(p.latitude);
  const double n = kLtpA / std::sqrt(1.0 - kLtpE2 * s * s);  // prime vertical radius of curvature
  return {(n + p.height) * c * std::cos(p.longitude), (n + p.height) * c * std::sin(p.longitude),
          (n * (1.0 - kLtpE2) + p.height) * s};
}

GeodeticPoint LocalTangentPlane::FromEcef(const Eigen::Vector3d& ecef) {
  const double x = ecef.x(), y = ecef.y(), z = ecef.z();
  const double p = std::hypot(x, y);  // distance from the polar axis
  GeodeticPoint g;
  g.longitude = p > 0.0 ? std::atan2(y, x) : 0.0;
  // atan2 gives -pi for the antimeridian approached from below (y = -0 or a rounding below 0).
  if (g.longitude <= -kLtpPi) g.longitude = kLtpPi;
  // Bowring's iteration on the reduced latitude beta: the latitude in closed form from beta, then
  // beta from that latitude. Started from the point's direction it converges to double precision in
  // two or three steps for points from well below the surface to far above it; the loop stops when
  // beta stops changing.
  double beta = std::atan2(z, (1.0 - kLtpF) * p);
  double latitude = beta;
  for (int i = 0; i < 10; ++i) {
    const double sb = std::sin(beta), cb = std::cos(beta);
    latitude = std::atan2(z + kLtpEp2 * kLtpB * sb * sb * sb, p - kLtpE2 * kLtpA * cb * cb * cb);
    const double next = std::atan2((1.0 - kLtpF) * std::sin(latitude), std::cos(latitude));
    const bool converged = std::abs(next - beta) < 1e-15;
    beta = next;
    if (converged) break;
  }
  g.latitude = latitude;
  // Height along the normal in a form that divides by neither cos nor sin of the latitude, so it
  // is as accurate at the poles as at the equator: p cos(lat) + z sin(lat) - a^2 / N.
  const double s = std::sin(latitude), c = std::cos(latitude);
  g.height = p * c + z * s - kLtpA * std::sqrt(1.0 - kLtpE2 * s * s);
  return g;
}

Eigen::Matrix3d LocalTangentPlane::R_ecef_enu(const GeodeticPoint& p) {
  const double sl = std::sin(p.latitude), cl = std::cos(p.latitude);
  const double so = std::sin(p.longitude), co = std::cos(p.longitude);
  Eigen::Matrix3d R;
  R.col(0) << -so, co, 0.0;            // east
  R.col(1) << -sl * co, -sl * so, cl;  // north
  R.col(2) << cl * co, cl * so, sl;    // up
  return R;
}

}  // namespace cairn
