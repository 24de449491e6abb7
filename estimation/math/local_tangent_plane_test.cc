#include "estimation/math/local_tangent_plane.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/LU>
#include <gtest/gtest.h>

#include "common/angles.h"

namespace cairn {
namespace {

constexpr double kLtpTestA = 6378137.0;       // WGS84 semi-major axis, m
constexpr double kLtpTestB = 6356752.314245;  // WGS84 semi-minor axis as published, m
constexpr double kLtpTestPi = 3.14159265358979323846;

GeodeticPoint LtpDeg(double lat_deg, double lon_deg, double height) {
  return {lat_deg * kDegree, lon_deg * kDegree, height};
}

// Longitude difference wrapped into (-pi, pi].
double LtpLonDiff(double a, double b) { return std::remainder(a - b, 2 * kLtpTestPi); }

// Length along the ellipsoid between two points of one meridian or one parallel: the sum of many
// short chords (each shorter than its arc by a relative 1e-11).
double LtpArc(const LocalTangentPlane& plane, const GeodeticPoint& from, const GeodeticPoint& to) {
  constexpr int kSteps = 1000;
  double length = 0.0;
  Eigen::Vector3d previous = plane.ToEnu(from);
  for (int k = 1; k <= kSteps; ++k) {
    const double s = static_cast<double>(k) / kSteps;
    const Eigen::Vector3d next = plane.ToEnu({from.latitude + s * (to.latitude - from.latitude),
                                              from.longitude + s * (to.longitude - from.longitude), 0.0});
    length += (next - previous).norm();
    previous = next;
  }
  return length;
}

const std::vector<GeodeticPoint>& LtpDatums() {
  static const std::vector<GeodeticPoint> datums = {
      LtpDeg(0, 0, 0),              // equator, prime meridian
      LtpDeg(45, 7.5, 450),         // mid latitude
      LtpDeg(37.72, 14.99, 2650),   // an analogue site on a volcano
      LtpDeg(89.99, 30, 2800),      // 1.1 km from the north pole
      LtpDeg(90, 0, 0),             // the pole itself
      LtpDeg(-33.4, -70.6, 600),    // southern and western hemispheres
      LtpDeg(-89.5, -120, 2835),    // near the south pole
      LtpDeg(12.0, 179.9995, 10),   // 55 m west of the dateline
      LtpDeg(-16.5, -179.99, -30),  // just east of it, below the ellipsoid
  };
  return datums;
}

TEST(LocalTangentPlaneTest, KeepsTheDatum) {
  const GeodeticPoint d = LtpDeg(-33.4, -70.6, 600);
  const LocalTangentPlane plane(d);
  EXPECT_EQ(plane.datum().latitude, d.latitude);
  EXPECT_EQ(plane.datum().longitude, d.longitude);
  EXPECT_EQ(plane.datum().height, d.height);
  EXPECT_LT(plane.ToEnu(d).norm(), 1e-9);
}

// Points whose coordinates follow from the ellipsoid's axes alone.
TEST(LocalTangentPlaneTest, AxesOfTheEllipsoid) {
  EXPECT_LT((LocalTangentPlane::ToEcef(LtpDeg(0, 0, 0)) - Eigen::Vector3d(kLtpTestA, 0, 0)).norm(), 1e-9);
  EXPECT_LT((LocalTangentPlane::ToEcef(LtpDeg(90, 0, 0)) - Eigen::Vector3d(0, 0, kLtpTestB)).norm(), 1e-6);
  EXPECT_LT((LocalTangentPlane::ToEcef(LtpDeg(-90, 0, 0)) - Eigen::Vector3d(0, 0, -kLtpTestB)).norm(), 1e-6);
  const LocalTangentPlane equator(LtpDeg(0, 0, 0));
  // 90 deg east along the equator: a east of the datum and a below its horizon.
  EXPECT_LT((equator.ToEnu(LtpDeg(0, 90, 0)) - Eigen::Vector3d(kLtpTestA, 0, -kLtpTestA)).norm(), 1e-6);
  // The north pole: b north and a below.
  EXPECT_LT((equator.ToEnu(LtpDeg(90, 0, 0)) - Eigen::Vector3d(0, kLtpTestB, -kLtpTestA)).norm(), 1e-6);
  // The antipode, 2 a straight down.
  EXPECT_LT((equator.ToEnu(LtpDeg(0, 180, 0)) - Eigen::Vector3d(0, 0, -2 * kLtpTestA)).norm(), 1e-6);
}

// Lengths of one degree as geodesy tables give them for WGS84.
TEST(LocalTangentPlaneTest, LengthsOfOneDegree) {
  const LocalTangentPlane equator(LtpDeg(0, 0, 0));
  EXPECT_NEAR(LtpArc(equator, LtpDeg(0, 0, 0), LtpDeg(1, 0, 0)), 110574.0, 1.0);
  EXPECT_NEAR(LtpArc(equator, LtpDeg(0, 0, 0), LtpDeg(0, 1, 0)), 111319.49, 0.01);  // a * pi / 180
  const LocalTangentPlane mid(LtpDeg(45, 0, 0));
  EXPECT_NEAR(LtpArc(mid, LtpDeg(44.5, 0, 0), LtpDeg(45.5, 0, 0)), 111131.8, 0.1);
  EXPECT_NEAR(LtpArc(mid, LtpDeg(45, -0.5, 0), LtpDeg(45, 0.5, 0)), 78847.0, 1.0);
  const LocalTangentPlane polar(LtpDeg(89.5, 0, 0));
  EXPECT_NEAR(LtpArc(polar, LtpDeg(89, 0, 0), LtpDeg(90, 0, 0)), 111694.0, 1.0);
}

TEST(LocalTangentPlaneTest, StraightAboveTheDatumIsUp) {
  for (const GeodeticPoint& d : LtpDatums()) {
    const LocalTangentPlane plane(d);
    for (double h : {-100.0, 1.0, 1000.0, 100000.0}) {
      EXPECT_LT((plane.ToEnu({d.latitude, d.longitude, d.height + h}) - Eigen::Vector3d(0, 0, h)).norm(),
                1e-6)
          << d.latitude << " " << d.longitude << " " << h;
    }
  }
}

// The inverse against the closed-form forward conversion, from below the ellipsoid to 100 km up,
// pole to pole, on both sides of the dateline.
TEST(LocalTangentPlaneTest, GeodeticFromEcefIsExact) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> lat(-kLtpTestPi / 2, kLtpTestPi / 2), lon(-kLtpTestPi, kLtpTestPi);
  std::vector<GeodeticPoint> points;
  for (double h : {-5000.0, -500.0, 0.0, 10.0, 3000.0, 20000.0, 100000.0}) {
    for (double lat_deg : {-90.0, -89.9999999, -60.0, -1e-9, 0.0, 30.0, 45.0, 89.9, 90.0}) {
      for (double lon_deg : {-180.0, -179.9999, -90.0, 0.0, 14.99, 135.0, 179.9999, 180.0}) {
        points.push_back(LtpDeg(lat_deg, lon_deg, h));
      }
    }
    for (int i = 0; i < 2000; ++i) points.push_back({lat(rng), lon(rng), h});
  }
  for (const GeodeticPoint& p : points) {
    const GeodeticPoint q = LocalTangentPlane::FromEcef(LocalTangentPlane::ToEcef(p));
    EXPECT_NEAR(q.latitude, p.latitude, 1e-12) << p.latitude << " " << p.longitude << " " << p.height;
    EXPECT_NEAR(q.height, p.height, 1e-6) << p.latitude << " " << p.longitude << " " << p.height;
    // At a pole every longitude is the same point.
    EXPECT_LT(std::abs(LtpLonDiff(q.longitude, p.longitude)) * std::cos(p.latitude), 1e-12) << p.longitude;
    EXPECT_GT(q.longitude, -kLtpTestPi);
    EXPECT_LE(q.longitude, kLtpTestPi);
  }
}

TEST(LocalTangentPlaneTest, RoundTripsUpTo100KilometresFromEveryDatum) {
  for (const GeodeticPoint& d : LtpDatums()) {
    const LocalTangentPlane plane(d);
    for (double distance : {0.0, 0.3, 100.0, 10000.0, 100000.0}) {
      for (int k = 0; k < 8; ++k) {
        for (double up : {-400.0, 0.0, 20.0, 5000.0}) {
          const double azimuth = 2 * kLtpTestPi * k / 8 + 0.1;
          const Eigen::Vector3d enu(distance * std::sin(azimuth), distance * std::cos(azimuth), up);
          const GeodeticPoint g = plane.ToGeodetic(enu);
          const Eigen::Vector3d back = plane.ToEnu(g);
          EXPECT_LT((back - enu).norm(), 1e-6) << d.latitude << " " << d.longitude << " " << enu.transpose();
          const GeodeticPoint again = plane.ToGeodetic(back);
          EXPECT_NEAR(again.latitude, g.latitude, 1e-12);
          EXPECT_NEAR(again.height, g.height, 1e-6);
          EXPECT_LT(std::abs(LtpLonDiff(again.longitude, g.longitude)) * std::cos(g.latitude), 1e-12);
        }
      }
    }
  }
}

// Near the datum the plane is the tangent plane: 1 km east is 1 km east, and the ground drops
// below the horizon as d^2 / 2R.
TEST(LocalTangentPlaneTest, LocallyFlatWithTheEarthsCurvature) {
  const LocalTangentPlane plane(LtpDeg(45, 7.5, 450));
  const GeodeticPoint east = plane.ToGeodetic({1000.0, 0.0, 0.0});
  EXPECT_NEAR(east.latitude, 45 * kDegree, 1e-7);  // the horizon is not a parallel
  EXPECT_GT(east.longitude, 7.5 * kDegree);
  const Eigen::Vector3d ground = plane.ToEnu({45 * kDegree, east.longitude, 450.0});
  EXPECT_NEAR(ground.x(), 1000.0, 0.01);
  EXPECT_NEAR(ground.z(), -1000.0 * 1000.0 / (2 * 6.38e6), 0.002);
}

TEST(LocalTangentPlaneTest, RotationOfLocalAxesIsIdentityAtTheDatumAndOrthonormal) {
  for (const GeodeticPoint& d : LtpDatums()) {
    const LocalTangentPlane plane(d);
    EXPECT_LT((plane.R_datum_local(d) - Eigen::Matrix3d::Identity()).norm(), 1e-14);
    EXPECT_LT((plane.R_datum_local({d.latitude, d.longitude, d.height + 5000}) - Eigen::Matrix3d::Identity())
                  .norm(),
              1e-14);
    for (const Eigen::Vector3d& enu : {Eigen::Vector3d(100000, 0, 0), Eigen::Vector3d(-30000, 70000, 200),
                                       Eigen::Vector3d(0, -100000, -100)}) {
      const GeodeticPoint p = plane.ToGeodetic(enu);
      const Eigen::Matrix3d R = plane.R_datum_local(p);
      EXPECT_LT((R.transpose() * R - Eigen::Matrix3d::Identity()).norm(), 1e-14);
      EXPECT_NEAR(R.determinant(), 1.0, 1e-14);
      // Its columns are the directions in which p's height and latitude move it in the plane.
      const double dh = 1.0, dlat = 1e-7;
      const Eigen::Vector3d up = plane.ToEnu({p.latitude, p.longitude, p.height + dh}) - enu;
      const Eigen::Vector3d north = plane.ToEnu({p.latitude + dlat, p.longitude, p.height}) - enu;
      EXPECT_LT((R.col(2) - up.normalized()).norm(), 1e-8);
      EXPECT_LT((R.col(1) - north.normalized()).norm(), 1e-6);
    }
  }
}

}  // namespace
}  // namespace cairn
