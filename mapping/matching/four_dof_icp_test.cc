#include "mapping/matching/four_dof_icp.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "estimation/math/ordered_draws.h"
#include "mapping/matching/testing/icp_test_scene.h"

namespace cairn {
namespace {

const FourDofTransform kTruth(1.5, -0.8, 0.2, 0.9);  // T_a_b

// The truth moved by 0.3 m and 5 deg.
FourDofTransform Perturbed(const FourDofTransform& truth) {
  return FourDofTransform(truth.translation() + Eigen::Vector3d(0.2, -0.2, 0.1), truth.yaw() + 5.0 * kDegree);
}

Eigen::Vector4d Error(const FourDofTransform& estimate, const FourDofTransform& truth) {
  Eigen::Vector4d e = estimate.ToVector() - truth.ToVector();
  e(3) = WrapAngle(e(3));
  return e;
}

TEST(FourDofIcpTest, ConvergesFromAPerturbedStartOnNoiseFreeData) {
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(scene, -10.0, 2.0, FourDofTransform(), 0.0, 1);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(scene, -2.0, 10.0, kTruth.inverse(), 0.0, 2);
  const FourDofIcpResult r = FourDofIcp().Align(target, source, Perturbed(kTruth));
  ASSERT_TRUE(r.ok()) << r.status.ToString();
  EXPECT_TRUE(r.converged);
  const Eigen::Vector4d e = Error(r.T_a_b, kTruth);
  EXPECT_LT(e.head<3>().norm(), 1e-3) << e.transpose();
  EXPECT_LT(std::abs(e(3)), 0.01 * kDegree) << e.transpose();
  EXPECT_LT(r.rms, 1e-4);
  EXPECT_GT(r.inliers, 1000u);
  EXPECT_GT(r.overlap, 0.5);
  EXPECT_LE(r.iterations, 30);
  EXPECT_EQ(r.skipped_source + r.skipped_target, 0u);
  std::printf("noise-free: %lld iterations, %zu inliers of %zu, observability %.4f\n",
              static_cast<long long>(r.iterations), r.inliers, source.size(), r.observability);
}

TEST(FourDofIcpTest, ConvergesWithCentimetreNoiseOnDifferentSamples) {
  const std::vector<Eigen::Vector3d> scene_a = IcpTestScene(0.1, 0.5);
  const std::vector<Eigen::Vector3d> scene_b = IcpTestScene(0.1, 0.15);  // other points of the same surfaces
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(scene_a, -10.0, 2.0, FourDofTransform(), 0.01, 3);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(scene_b, -2.0, 10.0, kTruth.inverse(), 0.01, 4);
  const FourDofIcpResult r = FourDofIcp().Align(target, source, Perturbed(kTruth));
  ASSERT_TRUE(r.ok()) << r.status.ToString();
  const Eigen::Vector4d e = Error(r.T_a_b, kTruth);
  EXPECT_LT(e.head<3>().norm(), 0.005) << e.transpose();
  EXPECT_LT(std::abs(e(3)), 0.1 * kDegree) << e.transpose();
  // Point-to-plane residuals of two clouds with 1 cm noise each: about sqrt(2) cm.
  EXPECT_GT(r.rms, 0.008);
  EXPECT_LT(r.rms, 0.02);
  const Eigen::Vector4d sigma = r.covariance.diagonal().cwiseSqrt();
  EXPECT_TRUE(sigma.allFinite());
  EXPECT_GT(sigma.minCoeff(), 0.0);
  EXPECT_LT(sigma.head<3>().maxCoeff(), 0.005);
  std::printf("1 cm noise: %lld iterations, %zu inliers, rms %.4f m, observability %.4f\n",
              static_cast<long long>(r.iterations), r.inliers, r.rms, r.observability);
  std::printf("  error (mm, mm, mm, mdeg): %.2f %.2f %.2f %.2f, sigma: %.2f %.2f %.2f %.2f\n", e(0) * 1e3,
              e(1) * 1e3, e(2) * 1e3, e(3) / kDegree * 1e3, sigma(0) * 1e3, sigma(1) * 1e3, sigma(2) * 1e3,
              sigma(3) / kDegree * 1e3);
}

// Over repeated noisy trials the normalized estimation error squared e^T Sigma^-1 e of a
// consistent 4-D covariance averages 4; too small a covariance gives much more, too large much less.
double MeanNees(const IcpOptions& options, int trials, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double sum = 0.0;
  int used = 0;
  for (int t = 0; t < trials; ++t) {
    // Each trial samples the surfaces afresh: with one fixed sampling its discretization error
    // would be the same bias in every trial, which no noise covariance describes.
    const double offset_a = 0.5 + 0.5 * unit(rng);
    const std::vector<Eigen::Vector3d> scene_a = IcpTestScene(0.1, offset_a);
    const double offset_b = 0.5 + 0.5 * unit(rng);
    const std::vector<Eigen::Vector3d> scene_b = IcpTestScene(0.1, offset_b);
    const std::vector<Eigen::Vector3d> target = IcpTestCloud(scene_a, -10.0, 2.0, FourDofTransform(), 0.01, rng());
    const std::vector<Eigen::Vector3d> source = IcpTestCloud(scene_b, -2.0, 10.0, kTruth.inverse(), 0.01, rng());
    const Eigen::Vector3d dt = 0.2 * DrawVector3(unit, rng);
    const double dyaw = 3.0 * kDegree * unit(rng);
    const FourDofTransform start(kTruth.translation() + dt, kTruth.yaw() + dyaw);
    const FourDofIcpResult r = FourDofIcp(options).Align(target, source, start);
    EXPECT_TRUE(r.ok()) << r.status.ToString() << " trial " << t;
    if (!r.ok()) continue;
    const Eigen::Vector4d e = Error(r.T_a_b, kTruth);
    sum += e.dot(r.covariance.ldlt().solve(e));
    ++used;
  }
  return used > 0 ? sum / used : std::numeric_limits<double>::quiet_NaN();
}

TEST(FourDofIcpTest, CovarianceIsConsistentOverNoisyTrials) {
  const double nees = MeanNees(IcpOptions{}, 30, 17);
  std::printf("mean NEES over 30 trials: %.2f (4 expected)\n", nees);
  // 30 trials: the mean of chi^2(4) has a standard deviation of 0.5.
  EXPECT_GT(nees, 2.0);
  EXPECT_LT(nees, 7.0);
}

TEST(FourDofIcpTest, FlatPlaneIsDegenerate) {
  std::vector<Eigen::Vector3d> plane;
  SampleRect({-3.0, -3.0, 0.0}, {6.0, 0.0, 0.0}, {0.0, 6.0, 0.0}, 0.1, 0.5, &plane);
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(plane, -10.0, 10.0, FourDofTransform(), 0.01, 5);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(plane, -10.0, 10.0, kTruth.inverse(), 0.01, 6);
  const FourDofIcpResult r = FourDofIcp().Align(target, source, kTruth);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.degenerate);
  EXPECT_EQ(r.status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status.message().find("degenerate"), std::string::npos) << r.status.message();
  EXPECT_LT(r.observability, 0.005);
}

// Rolling ground without rocks (slopes up to about 7 %, as on the simulator's terrain) constrains
// x, y and yaw only weakly per point, but over thousands of points well enough: not degenerate.
TEST(FourDofIcpTest, RollingGroundIsObservable) {
  std::vector<Eigen::Vector3d> ground;
  SampleRect({-4.0, -4.0, 0.0}, {8.0, 0.0, 0.0}, {0.0, 8.0, 0.0}, 0.05, 0.5, &ground);
  for (Eigen::Vector3d& p : ground) p.z() = 0.1 * std::sin(p.x() / 1.5) * std::cos(p.y() / 1.7) + 0.03 * p.x();
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(ground, -10.0, 10.0, FourDofTransform(), 0.01, 9);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(ground, -10.0, 10.0, kTruth.inverse(), 0.01, 10);
  const FourDofTransform start(kTruth.translation() + Eigen::Vector3d(0.05, -0.05, 0.0), kTruth.yaw() + 1.0 * kDegree);
  const FourDofIcpResult r = FourDofIcp().Align(target, source, start);
  std::printf("rolling ground: observability %.4f, %zu inliers\n", r.observability, r.inliers);
  ASSERT_TRUE(r.ok()) << r.status.ToString();
  EXPECT_GT(r.observability, IcpOptions{}.min_observability);
  EXPECT_LT(r.observability, 0.005);  // what the first threshold called degenerate
  EXPECT_LT((r.T_a_b.translation() - kTruth.translation()).norm(), 0.03);
  EXPECT_LT(std::abs(r.T_a_b.yaw() - kTruth.yaw()), 0.2 * kDegree);
}

TEST(FourDofIcpTest, SingleWallLeavesTheMotionAlongItFree) {
  std::vector<Eigen::Vector3d> corridor;
  SampleRect({-3.0, -3.0, 0.0}, {6.0, 0.0, 0.0}, {0.0, 6.0, 0.0}, 0.1, 0.5, &corridor);
  SampleRect({-3.0, 1.0, 0.0}, {6.0, 0.0, 0.0}, {0.0, 0.0, 1.5}, 0.1, 0.5, &corridor);
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(corridor, -10.0, 10.0, FourDofTransform(), 0.01, 7);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(corridor, -10.0, 10.0, kTruth.inverse(), 0.01, 8);
  const FourDofIcpResult r = FourDofIcp().Align(target, source, kTruth);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.degenerate) << r.status.ToString();

  // A second wall across the first constrains it.
  SampleRect({-2.5, -3.0, 0.0}, {0.0, 4.0, 0.0}, {0.0, 0.0, 1.5}, 0.1, 0.5, &corridor);
  const std::vector<Eigen::Vector3d> target2 = IcpTestCloud(corridor, -10.0, 10.0, FourDofTransform(), 0.01, 7);
  const std::vector<Eigen::Vector3d> source2 = IcpTestCloud(corridor, -10.0, 10.0, kTruth.inverse(), 0.01, 8);
  const FourDofIcpResult r2 = FourDofIcp().Align(target2, source2, kTruth);
  EXPECT_TRUE(r2.ok()) << r2.status.ToString();
  EXPECT_FALSE(r2.degenerate);
}

TEST(FourDofIcpTest, NonFinitePointsAreSkippedAndCounted) {
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  std::vector<Eigen::Vector3d> target = IcpTestCloud(scene, -10.0, 2.0, FourDofTransform(), 0.0, 1);
  std::vector<Eigen::Vector3d> source = IcpTestCloud(scene, -2.0, 10.0, kTruth.inverse(), 0.0, 2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  for (size_t i = 0; i < target.size(); i += 50) target[i].x() = nan;
  for (size_t i = 7; i < source.size(); i += 40) source[i].z() = (i % 80 == 7) ? nan : -inf;
  const size_t nan_target = (target.size() + 49) / 50;
  const size_t nan_source = (source.size() - 7 + 39) / 40;
  const FourDofIcpResult r = FourDofIcp().Align(target, source, Perturbed(kTruth));
  ASSERT_TRUE(r.ok()) << r.status.ToString();
  EXPECT_EQ(r.skipped_target, nan_target);
  EXPECT_EQ(r.skipped_source, nan_source);
  const Eigen::Vector4d e = Error(r.T_a_b, kTruth);
  EXPECT_LT(e.head<3>().norm(), 1e-3);
  EXPECT_LT(std::abs(e(3)), 0.01 * kDegree);
  EXPECT_TRUE(r.covariance.allFinite());
}

TEST(FourDofIcpTest, EmptyAndNonFiniteOnlyInputsAreReported) {
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  const std::vector<Eigen::Vector3d> none;
  const FourDofIcpResult no_source = FourDofIcp().Align(scene, none, FourDofTransform());
  EXPECT_EQ(no_source.status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(no_source.status.message().find("source cloud is empty"), std::string::npos)
      << no_source.status.message();
  const FourDofIcpResult no_target = FourDofIcp().Align(none, scene, FourDofTransform());
  EXPECT_EQ(no_target.status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(no_target.status.message().find("target cloud is empty"), std::string::npos)
      << no_target.status.message();
  const std::vector<Eigen::Vector3d> nans(
      500, Eigen::Vector3d::Constant(std::numeric_limits<double>::quiet_NaN()));
  const FourDofIcpResult all_nan = FourDofIcp().Align(scene, nans, FourDofTransform());
  EXPECT_EQ(all_nan.status.code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(all_nan.skipped_source, 500u);
  EXPECT_NE(all_nan.status.message().find("500 non-finite"), std::string::npos) << all_nan.status.message();
  EXPECT_FALSE(all_nan.converged);
}

TEST(FourDofIcpTest, DisjointCloudsHaveTooFewOverlappingPoints) {
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  const FourDofIcpResult r = FourDofIcp().Align(scene, scene, FourDofTransform(20.0, 0.0, 0.0, 0.0));
  EXPECT_EQ(r.status.code(), StatusCode::kNotFound);
  EXPECT_NE(r.status.message().find("too few overlapping points"), std::string::npos) << r.status.message();
  EXPECT_EQ(r.inliers, 0u);
}

TEST(FourDofIcpTest, IterationLimitIsReportedAsNotConverged) {
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(scene, -10.0, 2.0, FourDofTransform(), 0.0, 1);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(scene, -2.0, 10.0, kTruth.inverse(), 0.0, 2);
  IcpOptions o;
  o.max_iterations = 2;
  const FourDofIcpResult r = FourDofIcp(o).Align(target, source, Perturbed(kTruth));
  EXPECT_FALSE(r.ok());
  EXPECT_FALSE(r.converged);
  EXPECT_EQ(r.iterations, 2);
  EXPECT_EQ(r.status.code(), StatusCode::kTimeout);
  EXPECT_NE(r.status.message().find("not converged"), std::string::npos) << r.status.message();

  IcpOptions bad;
  bad.min_correspondence_distance = 2.0;  // above max_correspondence_distance
  EXPECT_EQ(FourDofIcp(bad).Align(target, source, kTruth).status.code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace cairn
