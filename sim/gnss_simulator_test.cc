#include "sim/gnss_simulator.h"

#include <cmath>
#include <cstdio>
#include <map>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"

namespace cairn::sim {
namespace {

constexpr double kGnssTestKnot = 10.0;  // s between the test trajectory's control points

// A robot driving round a 40 m circle at 0.5 m/s, heading along it, for `duration` s.
BSplineTrajectory GnssCircle(double duration) {
  std::vector<Eigen::Vector3d> pos, euler;
  const int n = static_cast<int>(std::ceil(duration / kGnssTestKnot)) + 4;
  for (int i = 0; i < n; ++i) {
    const double th = 0.5 * kGnssTestKnot * (i - 1) / 40.0;
    pos.emplace_back(40.0 * std::cos(th), 40.0 * std::sin(th), 2.0 + std::sin(3 * th));
    euler.emplace_back(th + M_PI / 2, 0.1 * std::sin(th), 0.05 * std::cos(2 * th));
  }
  return BSplineTrajectory(kGnssTestKnot, std::move(pos), std::move(euler));
}

GnssSimulatorOptions GnssNoiseFree() {
  GnssSimulatorOptions o;
  o.enabled = true;
  o.sigma_horizontal = o.sigma_vertical = o.bias_sigma = 0.0;
  o.outage_rate = 0.0;
  return o;
}

const Timestamp kGnssTestStart = Timestamp::FromSeconds(1000.0);

// Error of each fix in the east-north-up axes at its antenna.
std::vector<Eigen::Vector3d> GnssErrors(const GnssSimulator& gnss, const std::vector<GnssTruth>& fixes) {
  std::vector<Eigen::Vector3d> errors;
  for (const GnssTruth& f : fixes) {
    const GeodeticPoint g{f.fix.latitude, f.fix.longitude, f.fix.height};
    errors.push_back(gnss.plane().R_datum_local(g).transpose() * (gnss.plane().ToEnu(g) - f.p_world_antenna));
  }
  return errors;
}

// Sample autocovariance of axis `a` at `lag` fixes (the fixes are consecutive epochs).
double GnssAutocovariance(const std::vector<Eigen::Vector3d>& e, int a, size_t lag) {
  double mean = 0.0;
  for (const Eigen::Vector3d& v : e) mean += v[a];
  mean /= static_cast<double>(e.size());
  double sum = 0.0;
  for (size_t k = 0; k + lag < e.size(); ++k) sum += (e[k][a] - mean) * (e[k + lag][a] - mean);
  return sum / static_cast<double>(e.size() - lag);
}

TEST(GnssSimulatorTest, DefaultsAreOffAndASingleFrequencyReceiver) {
  const GnssSimulatorOptions o;
  EXPECT_FALSE(o.enabled);
  const GnssSimulator gnss(o, 1, 0);
  const Eigen::Vector3d stated(1.5 * 1.5 + 1.0, 1.5 * 1.5 + 1.0, 3.0 * 3.0 + 1.0);
  EXPECT_LT((gnss.covariance() - Eigen::Matrix3d(stated.asDiagonal())).norm(), 1e-12);
  EXPECT_EQ(gnss.quality(), GnssQuality::kAutonomous);
  EXPECT_NEAR(gnss.plane().datum().latitude, 37.72 * kDegree, 1e-15);
  EXPECT_NEAR(gnss.plane().datum().longitude, 14.99 * kDegree, 1e-15);
  EXPECT_EQ(gnss.plane().datum().height, 2650.0);
  GnssSimulatorOptions rtk = o;
  rtk.sigma_horizontal = 0.01;
  rtk.sigma_vertical = 0.02;
  rtk.bias_sigma = 0.02;
  EXPECT_EQ(GnssSimulator(rtk, 1, 0).quality(), GnssQuality::kRtkFixed);
}

// Without noise a fix is the antenna, with world x east, y north and z up at the origin.
TEST(GnssSimulatorTest, NoiseFreeFixesAreTheAntennaOnTheEarth) {
  GnssSimulatorOptions o = GnssNoiseFree();
  o.rate_hz = 5.0;
  o.latency = 0.25;
  o.antenna_x = 0.3;
  o.antenna_y = -0.2;
  o.antenna_z = 1.1;
  const BSplineTrajectory trajectory = GnssCircle(60.0);
  const GnssSimulator gnss(o, 1, 0);
  const std::vector<GnssTruth> fixes = gnss.Generate(trajectory, kGnssTestStart, 60.0);
  // Measured every 0.2 s from 0 to 60 s; published 0.25 s later, so the last two come too late.
  ASSERT_EQ(fixes.size(), 299u);
  // Lengths of one radian of latitude and of longitude at the origin: the WGS84 radii of curvature
  // plus the origin's height.
  const double e2 = 6.69437999014e-3, s = std::sin(o.origin_latitude * kDegree);
  const double m = 6378137.0 * (1 - e2) / std::pow(1 - e2 * s * s, 1.5) + o.origin_height;
  const double n =
      (6378137.0 / std::sqrt(1 - e2 * s * s) + o.origin_height) * std::cos(o.origin_latitude * kDegree);
  for (size_t k = 0; k < fixes.size(); ++k) {
    const GnssTruth& f = fixes[k];
    EXPECT_EQ(f.fix.time, kGnssTestStart + Duration::Milliseconds(200 * static_cast<int64_t>(k)));
    EXPECT_EQ(f.published, f.fix.time + Duration::Milliseconds(250));
    const Eigen::Isometry3d T_world_body =
        trajectory.Evaluate((f.fix.time - kGnssTestStart).seconds()).T_world_body;
    const Eigen::Vector3d p = T_world_body * Eigen::Vector3d(0.3, -0.2, 1.1);
    EXPECT_LT((f.p_world_antenna - p).norm(), 1e-12);
    EXPECT_LT((gnss.plane().ToEnu({f.fix.latitude, f.fix.longitude, f.fix.height}) - p).norm(), 1e-6);
    // Within 45 m of the origin the plane is flat to a few mm.
    EXPECT_NEAR((f.fix.longitude - o.origin_longitude * kDegree) * n, p.x(), 0.01);
    EXPECT_NEAR((f.fix.latitude - o.origin_latitude * kDegree) * m, p.y(), 0.01);
    EXPECT_NEAR(f.fix.height - o.origin_height, p.z(), 0.01);
    EXPECT_EQ(f.fix.quality, GnssQuality::kRtkFixed);
    EXPECT_EQ(f.fix.satellites, 12);
    // A stated accuracy of 1 mm, not a singular covariance.
    EXPECT_NEAR(f.fix.covariance(0, 0), 1e-6, 1e-12);
  }
}

// Over 200000 fixes (3300 bias correlation times) the sample statistics are within a few per
// cent of the model: total sigma, white sigma (from differences of consecutive errors) and the
// bias's autocovariance at 30 s and 300 s.
TEST(GnssSimulatorTest, ErrorStatisticsMatchTheConfiguredSigmas) {
  GnssSimulatorOptions o;
  o.enabled = true;
  o.rate_hz = 1.0;
  o.latency = 0.0;
  o.outage_rate = 0.0;
  const double duration = 200000.0;
  const GnssSimulator gnss(o, 3, 0);
  const std::vector<GnssTruth> fixes = gnss.Generate(GnssCircle(duration), kGnssTestStart, duration);
  ASSERT_EQ(fixes.size(), 200001u);
  const std::vector<Eigen::Vector3d> e = GnssErrors(gnss, fixes);
  const double phi = std::exp(-1.0 / o.bias_time_constant);
  for (int a = 0; a < 3; ++a) {
    SCOPED_TRACE(a);
    const double white = a < 2 ? o.sigma_horizontal : o.sigma_vertical;
    double mean = 0.0;
    for (const Eigen::Vector3d& v : e) mean += v[a];
    mean /= static_cast<double>(e.size());
    const double total = std::sqrt(GnssAutocovariance(e, a, 0));
    double diff2 = 0.0;
    for (size_t k = 1; k < e.size(); ++k) diff2 += (e[k][a] - e[k - 1][a]) * (e[k][a] - e[k - 1][a]);
    diff2 /= static_cast<double>(e.size() - 1);
    // E[(e_k+1 - e_k)^2] = 2 sigma^2 + 2 bias_sigma^2 (1 - phi).
    const double white_estimate = std::sqrt((diff2 - 2 * o.bias_sigma * o.bias_sigma * (1 - phi)) / 2);
    const double c30 = GnssAutocovariance(e, a, 30), c300 = GnssAutocovariance(e, a, 300);
    std::printf(
        "axis %d: mean %+.4f m, sigma %.4f m (model %.4f), white %.4f m (model %.4f), "
        "autocovariance 30 s %.4f m^2 (model %.4f), 300 s %.4f m^2 (model %.4f)\n",
        a, mean, total, std::sqrt(gnss.covariance()(a, a)), white_estimate, white, c30, std::pow(phi, 30),
        c300, std::pow(phi, 300));
    EXPECT_NEAR(mean, 0.0, 0.1);
    EXPECT_NEAR(total / std::sqrt(gnss.covariance()(a, a)), 1.0, 0.03);
    EXPECT_NEAR(white_estimate / white, 1.0, 0.02);
    EXPECT_NEAR(c30, o.bias_sigma * o.bias_sigma * std::pow(phi, 30), 0.12);
    EXPECT_NEAR(c300, o.bias_sigma * o.bias_sigma * std::pow(phi, 300), 0.12);
  }
}

TEST(GnssSimulatorTest, OutagesRemoveFixesAndLeaveTheOthersAsTheyWere) {
  GnssSimulatorOptions o;
  o.enabled = true;
  o.rate_hz = 1.0;
  o.latency = 0.0;
  o.outage_rate = 0.01;
  o.outage_mean_duration = 20.0;
  const double duration = 100000.0;
  const BSplineTrajectory trajectory = GnssCircle(duration);
  const std::vector<GnssTruth> with = GnssSimulator(o, 5, 0).Generate(trajectory, kGnssTestStart, duration);
  o.outage_rate = 0.0;
  const std::vector<GnssTruth> without =
      GnssSimulator(o, 5, 0).Generate(trajectory, kGnssTestStart, duration);
  ASSERT_EQ(without.size(), 100001u);
  // Alternating renewal: the fraction of time out is rate * mean / (1 + rate * mean) = 1/6.
  const double missing = 1.0 - static_cast<double>(with.size()) / static_cast<double>(without.size());
  size_t gaps = 0, removed = 0;
  for (size_t k = 1; k < with.size(); ++k) {
    const int64_t step = (with[k].fix.time - with[k - 1].fix.time).nanoseconds() / 1000000000;
    if (step > 1) {
      ++gaps;
      removed += static_cast<size_t>(step - 1);
    }
  }
  const double mean_gap = static_cast<double>(removed) / static_cast<double>(gaps);
  std::printf("outages: %zu, %.2f %% of fixes missing (model %.2f %%), mean outage %.2f s (model 20)\n", gaps,
              100 * missing, 100.0 / 6, mean_gap);
  EXPECT_NEAR(missing, 1.0 / 6, 0.02);
  EXPECT_NEAR(static_cast<double>(gaps), duration * 0.01 / 1.2, 100.0);
  EXPECT_NEAR(mean_gap, 20.0, 2.0);
  // The fixes that remain are the same fixes.
  std::map<int64_t, const GnssTruth*> by_time;
  for (const GnssTruth& f : without) by_time[f.fix.time.nanoseconds()] = &f;
  for (const GnssTruth& f : with) {
    const GnssTruth* g = by_time.at(f.fix.time.nanoseconds());
    ASSERT_EQ(f.fix.latitude, g->fix.latitude);
    ASSERT_EQ(f.fix.height, g->fix.height);
  }
}

TEST(GnssSimulatorTest, TheSeedDecidesTheFixes) {
  GnssSimulatorOptions o;
  o.enabled = true;
  o.outage_rate = 0.05;
  const BSplineTrajectory trajectory = GnssCircle(300.0);
  const auto fixes = [&](uint64_t seed, uint64_t stream) {
    return GnssSimulator(o, seed, stream).Generate(trajectory, kGnssTestStart, 300.0);
  };
  const std::vector<GnssTruth> a = fixes(7, 0), b = fixes(7, 0), c = fixes(8, 0), d = fixes(7, 1);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_GT(a.size(), 100u);
  ASSERT_LT(a.size(), 300u);  // with outages
  for (size_t k = 0; k < a.size(); ++k) {
    EXPECT_EQ(a[k].fix.time, b[k].fix.time);
    EXPECT_EQ(a[k].fix.latitude, b[k].fix.latitude);
    EXPECT_EQ(a[k].fix.longitude, b[k].fix.longitude);
    EXPECT_EQ(a[k].fix.height, b[k].fix.height);
  }
  EXPECT_NE(a.front().fix.latitude, c.front().fix.latitude);
  EXPECT_NE(a.front().fix.latitude, d.front().fix.latitude);
}

}  // namespace
}  // namespace cairn::sim
