#include "daemon/pipeline/gnss_fix_factors.h"

#include <cmath>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "estimation/graph/pose_factors.h"
#include "estimation/graph/slam_graph.h"

namespace cairn {
namespace {

Pose3 GnssTestPose(double x, double y, double z, double yaw) {
  return Pose3{Eigen::Vector3d(x, y, z),
               Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))};
}

GnssFixOptions FixOptionsNear(double latitude_deg, double longitude_deg) {
  GnssFixOptions o;
  o.enabled = true;
  o.datum_latitude = latitude_deg;
  o.datum_longitude = longitude_deg;
  o.datum_height = 350.0;
  o.antenna_x = 0.2;
  o.antenna_z = 0.8;
  return o;
}

TEST(GnssFixFactorsTest, FitDatumRecoversYawAndTranslation) {
  const Pose3 truth = GnssTestPose(12.0, -4.0, 1.5, 2.2);
  std::vector<Eigen::Vector3d> world, enu;
  std::vector<double> weights;
  for (int i = 0; i < 5; ++i) {
    const Eigen::Vector3d z(3.0 * i, 2.0 * i * i, 0.1 * i);
    enu.push_back(z);
    world.push_back(truth.t + truth.q * z);
    weights.push_back(1.0 + i);
  }
  const Expected<Pose3> fit = GnssFixFactors::FitDatum(world, enu, weights);
  ASSERT_TRUE(fit.ok());
  EXPECT_LT((fit->t - truth.t).norm(), 1e-9);
  EXPECT_LT(fit->q.angularDistance(truth.q), 1e-9);
  EXPECT_FALSE(GnssFixFactors::FitDatum({world[0]}, {enu[0]}, {1.0}).ok());
  EXPECT_FALSE(GnssFixFactors::FitDatum({world[0], world[0]}, {enu[0], enu[0]}, {1.0, 1.0}).ok());
}

TEST(GnssFixFactorsTest, RefusesFixesWithoutSolutionOrWithBadAccuracy) {
  const GnssFixFactors gnss(FixOptionsNear(47.0, 8.0));
  GnssFix fix;
  fix.latitude = 47.0 * std::numbers::pi / 180;
  fix.longitude = 8.0 * std::numbers::pi / 180;
  fix.quality = GnssQuality::kAutonomous;
  EXPECT_TRUE(gnss.Check(fix).ok());
  GnssFix none = fix;
  none.quality = GnssQuality::kNone;
  EXPECT_FALSE(gnss.Check(none).ok());
  GnssFix nan = fix;
  nan.height = std::nan("");
  EXPECT_FALSE(gnss.Check(nan).ok());
  GnssFix poor = fix;
  poor.covariance = Eigen::Matrix3d::Identity() * 400.0;  // 20 m
  EXPECT_NE(gnss.Check(poor).ToString().find("max_sigma"), std::string::npos);
  GnssFix negative = fix;
  negative.covariance(2, 2) = -1.0;
  EXPECT_FALSE(gnss.Check(negative).ok());
}

// A robot drives a 60 m x 40 m rectangle on odometry that drifts (a random walk), with noisy
// fixes of an antenna off its centre. The graph's world is its first pose; the datum lies
// elsewhere with an unknown yaw. The fixes must start the datum once it can be fixed, recover its
// yaw, and bring the drifted trajectory back.
constexpr double kStepSigmaT = 0.05;  // m per 2 m step
constexpr double kStepSigmaR = 0.01;  // rad per step

struct DriftingRectangle {
  std::vector<Pose3> truth;     // T_world_body
  std::vector<Pose3> odometry;  // measured T_i_i+1
};

double AlignedRmse(const std::vector<Eigen::Vector3d>& estimate, const std::vector<Eigen::Vector3d>& truth) {
  const Expected<Pose3> T = GnssFixFactors::FitDatum(estimate, truth, std::vector<double>(truth.size(), 1.0));
  double sq = 0;
  for (size_t i = 0; i < truth.size(); ++i) sq += (T->t + T->q * truth[i] - estimate[i]).squaredNorm();
  return std::sqrt(sq / static_cast<double>(truth.size()));
}

DriftingRectangle MakeRectangle() {
  DriftingRectangle r;
  double x = 0, y = 0, yaw = 0;
  const double legs[4] = {60, 40, 60, 40};
  for (double leg : legs) {
    for (int s = 0; s < static_cast<int>(leg / 2.0); ++s) {
      r.truth.push_back(GnssTestPose(x, y, 0.0, yaw));
      x += 2.0 * std::cos(yaw);
      y += 2.0 * std::sin(yaw);
    }
    r.truth.push_back(GnssTestPose(x, y, 0.0, yaw));
    yaw += std::numbers::pi / 2;
  }
  // Odometry with random-walk drift, its noise as its information says.
  std::mt19937 rng(11);
  std::normal_distribution<double> step_noise(0.0, 1.0);
  for (size_t i = 0; i + 1 < r.truth.size(); ++i) {
    const Eigen::Vector3d dt(step_noise(rng), step_noise(rng), step_noise(rng));
    const Eigen::Vector3d dr(step_noise(rng), step_noise(rng), step_noise(rng));
    const Pose3 noise{kStepSigmaT * dt,
                      Eigen::Quaterniond(Eigen::AngleAxisd(kStepSigmaR * dr.norm(), dr.normalized()))};
    r.odometry.push_back(r.truth[i].Inverse() * r.truth[i + 1] * noise);
  }
  return r;
}

TEST(GnssFixFactorsTest, FixesStartTheDatumAndRemoveTheDrift) {
  const GnssFixOptions options = FixOptionsNear(-33.9, 151.2);
  GnssFixFactors gnss(options);
  const LocalTangentPlane plane(GeodeticPoint{options.datum_latitude * std::numbers::pi / 180,
                                              options.datum_longitude * std::numbers::pi / 180,
                                              options.datum_height});
  const Pose3 T_world_enu = GnssTestPose(-130.0, 45.0, -2.0, 2.5);  // unknown to the graph
  const Eigen::Vector3d antenna(options.antenna_x, options.antenna_y, options.antenna_z);
  const DriftingRectangle rect = MakeRectangle();
  constexpr double kSigma = 1.0;
  std::mt19937 rng(4);
  std::normal_distribution<double> noise(0.0, kSigma);

  SlamGraph graph;
  SlamGraph odometry_only;
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  prior.information = Matrix6d::Identity() * 1e6;
  ASSERT_TRUE(graph.AddFactor(prior).ok());
  ASSERT_TRUE(odometry_only.AddFactor(prior).ok());
  size_t factors_before_datum = 0;
  for (size_t i = 0; i < rect.truth.size(); ++i) {
    const uint64_t s = VariableKey(VariableKind::kSubmap, 'a', i),
                   x = VariableKey(VariableKind::kRobotPose, 'a', i);
    if (i > 0) {
      SlamFactor w;
      w.kind = FactorKind::kFrameSwitch;
      w.a = VariableKey(VariableKind::kSubmap, 'a', i - 1);
      w.b = s;
      w.z = rect.odometry[i - 1];
      w.information.diagonal() << Eigen::Vector3d::Constant(1 / (kStepSigmaT * kStepSigmaT)),
          Eigen::Vector3d::Constant(1 / (kStepSigmaR * kStepSigmaR));
      ASSERT_TRUE(graph.AddFactor(w).ok());
      ASSERT_TRUE(odometry_only.AddFactor(w).ok());
    }
    SlamFactor v;
    v.kind = FactorKind::kFilterEstimate;
    v.a = s;
    v.b = x;
    v.information = Matrix6d::Identity() * 1e6;
    ASSERT_TRUE(graph.AddFactor(v).ok());
    ASSERT_TRUE(odometry_only.AddFactor(v).ok());
    // The fix, as the receiver reports it.
    const Pose3& T = rect.truth[i];
    const Eigen::Vector3d enu = T_world_enu.Inverse().t + T_world_enu.q.conjugate() * (T.t + T.q * antenna) +
                                Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
    const GeodeticPoint p = plane.ToGeodetic(enu);
    GnssFix fix;
    fix.latitude = p.latitude;
    fix.longitude = p.longitude;
    fix.height = p.height;
    fix.quality = GnssQuality::kAutonomous;
    // Reported in the fix's own ENU axes: isotropic, so the same in the datum's.
    fix.covariance = Eigen::Matrix3d::Identity() * kSigma * kSigma;
    ASSERT_TRUE(gnss.Check(fix).ok());
    const std::vector<SlamFactor> factors = gnss.Add(fix, x, *graph.Pose(x), gnss.antenna());
    if (!gnss.counts().datum_started) {
      EXPECT_TRUE(factors.empty());
      ++factors_before_datum;
    }
    for (const SlamFactor& f : factors) ASSERT_TRUE(graph.AddFactor(f).ok()) << static_cast<int>(f.kind);
    graph.Update();
  }
  // A 0.05 rad yaw from 1 m fixes 2 m apart on a line takes about 11 of them.
  EXPECT_GE(factors_before_datum, 9u);
  EXPECT_LE(factors_before_datum, 12u);
  EXPECT_EQ(gnss.counts().factors, rect.truth.size());
  graph.SolveFull();
  odometry_only.SolveFull();
  // The world is the first pose, which the rest is tied to only through odometry: compare the
  // trajectories' shapes after a yaw-and-translation alignment, and the geo-referenced positions
  // (through the datum) directly.
  std::vector<Eigen::Vector3d> truth, fixed, drifted, truth_enu, fixed_enu;
  const Pose3 datum = *graph.Pose(GnssFixFactors::DatumKey());
  for (size_t i = 0; i < rect.truth.size(); ++i) {
    const uint64_t x = VariableKey(VariableKind::kRobotPose, 'a', i);
    truth.push_back(rect.truth[i].t);
    fixed.push_back(graph.Pose(x)->t);
    drifted.push_back(odometry_only.Pose(x)->t);
    truth_enu.push_back(T_world_enu.Inverse().t + T_world_enu.q.conjugate() * rect.truth[i].t);
    fixed_enu.push_back(datum.Inverse().t + datum.q.conjugate() * fixed.back());
  }
  const double fixed_rmse = AlignedRmse(fixed, truth), drifted_rmse = AlignedRmse(drifted, truth);
  double enu_sq = 0;
  for (size_t i = 0; i < truth.size(); ++i) enu_sq += (fixed_enu[i] - truth_enu[i]).squaredNorm();
  const double enu_rmse = std::sqrt(enu_sq / static_cast<double>(truth.size()));
  EXPECT_GT(drifted_rmse, 0.8);  // the drift is real (0.95 to 2.6 m over seeds 11-15)
  EXPECT_LT(fixed_rmse, 0.5 * drifted_rmse);
  // Better than the fixes themselves (1.7 m RMS in 3-D).
  EXPECT_LT(enu_rmse, 0.6 * kSigma);
  EXPECT_LT(datum.q.angularDistance(T_world_enu.q), 0.05);
  EXPECT_TRUE(graph.Unconnected().empty());
  // The datum's marginal covariance exists (the problem stays well posed).
  EXPECT_TRUE(graph.Covariances({GnssFixFactors::DatumKey()}).ok());
}

TEST(GnssFixFactorsTest, GraphRefusesFixesOnUnknownOrFloatingPoses) {
  SlamGraph graph;
  SlamFactor f;
  f.kind = FactorKind::kGnssPosition;
  f.a = GnssFixFactors::DatumKey();
  f.b = VariableKey(VariableKind::kRobotPose, 'a', 3);
  EXPECT_FALSE(graph.AddFactor(f).ok());
  SlamFactor wrong = f;
  wrong.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  EXPECT_NE(graph.AddFactor(wrong).ToString().find("does not fit"), std::string::npos);
}

TEST(GnssFixFactorsTest, AFloatingComponentIsPlacedRigidlyAndJoinsTheOwn) {
  SlamGraph graph;
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = VariableKey(VariableKind::kSubmap, 'a', 0);
  ASSERT_TRUE(graph.AddFactor(prior).ok());
  SlamFactor w;  // b's two origins, floating
  w.kind = FactorKind::kFrameSwitch;
  w.a = VariableKey(VariableKind::kSubmap, 'b', 0);
  w.b = VariableKey(VariableKind::kSubmap, 'b', 1);
  w.z = GnssTestPose(5.0, 0.0, 0.0, 0.5);
  ASSERT_TRUE(graph.AddFactor(w).ok());
  EXPECT_EQ(graph.Unconnected().size(), 2u);
  EXPECT_FALSE(graph.PlaceComponent(prior.a, Pose3()).ok());  // already the own robot's
  EXPECT_FALSE(graph.PlaceComponent(VariableKey(VariableKind::kSubmap, 'c', 0), Pose3()).ok());
  const Pose3 correction = GnssTestPose(10.0, -3.0, 0.0, 1.2);
  const Pose3 before = *graph.Pose(w.b);
  ASSERT_TRUE(graph.PlaceComponent(w.b, correction).ok());
  EXPECT_TRUE(graph.Unconnected().empty());
  const Pose3 after = *graph.Pose(w.b), expected = correction * before;
  EXPECT_LT((after.t - expected.t).norm(), 1e-12);
  EXPECT_LT(after.q.angularDistance(expected.q), 1e-12);
}

}  // namespace
}  // namespace cairn
