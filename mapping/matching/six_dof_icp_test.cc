#include "mapping/matching/six_dof_icp.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"
#include "mapping/matching/four_dof_icp.h"
#include "mapping/matching/testing/icp_test_scene.h"

namespace cairn {
namespace {

// T_a_b with a roll and pitch that the 4-DoF refinement cannot express.
Eigen::Isometry3d TiltedTruth() {
  Eigen::Isometry3d T = FourDofTransform(1.5, -0.8, 0.2, 0.9).ToIsometry();
  T.linear() = T.linear() * so3::Exp(Eigen::Vector3d(3.0, -2.0, 0.0) * kDegree);
  return T;
}

// (translation error, rotation error) of `estimate` against `truth`, in A's frame.
Eigen::Matrix<double, 6, 1> ErrorOf(const Eigen::Isometry3d& estimate, const Eigen::Isometry3d& truth) {
  Eigen::Matrix<double, 6, 1> e;
  e << estimate.translation() - truth.translation(), so3::Log(Eigen::Matrix3d(estimate.linear() * truth.linear().transpose()));
  return e;
}

Eigen::Isometry3d Nudged(const Eigen::Isometry3d& truth, const Eigen::Vector3d& dt, const Eigen::Vector3d& dw) {
  Eigen::Isometry3d T = truth;
  T.linear() = so3::Exp(dw) * truth.linear();
  T.translation() += dt;
  return T;
}

TEST(SixDofIcpTest, RecoversRollAndPitchFromAPerturbedStart) {
  const Eigen::Isometry3d truth = TiltedTruth();
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(scene, -10.0, 2.0, Eigen::Isometry3d::Identity(), 0.0, 1);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(scene, -2.0, 10.0, truth.inverse(), 0.0, 2);
  const Eigen::Isometry3d start =
      Nudged(truth, {0.2, -0.2, 0.1}, Eigen::Vector3d(2.0, -2.0, 5.0) * kDegree);
  const SixDofIcpResult r = SixDofIcp().Align(target, source, start);
  ASSERT_TRUE(r.ok()) << r.status.ToString();
  const Eigen::Matrix<double, 6, 1> e = ErrorOf(r.T_a_b, truth);
  EXPECT_LT(e.head<3>().norm(), 1e-3) << e.transpose();
  EXPECT_LT(e.tail<3>().norm(), 0.01 * kDegree) << e.transpose();
  EXPECT_LT(r.rms, 1e-4);
  EXPECT_GT(r.inliers, 1000u);

  // The 4-DoF refinement from the same start keeps roll and pitch at zero: its best fit leaves a
  // residual far above the 6-DoF one.
  const FourDofIcpResult r4 = FourDofIcp().Align(target, source, FourDofTransform::ProjectIsometry(start));
  EXPECT_GT(r4.rms, 50.0 * r.rms + 1e-3) << r4.status.ToString();
  std::printf("tilted truth: 6-DoF rms %.2e m in %lld iterations, 4-DoF rms %.4f m\n", r.rms,
              static_cast<long long>(r.iterations), r4.rms);
}

// On gravity-aligned clouds it finds no tilt, and agrees with the 4-DoF refinement.
TEST(SixDofIcpTest, AgreesWithTheFourDofRefinementOnLevelClouds) {
  const FourDofTransform truth(1.5, -0.8, 0.2, 0.9);
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(IcpTestScene(0.1, 0.5), -10.0, 2.0, FourDofTransform(), 0.01, 3);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(IcpTestScene(0.1, 0.15), -2.0, 10.0, truth.inverse(), 0.01, 4);
  const FourDofTransform start(truth.translation() + Eigen::Vector3d(0.2, -0.2, 0.1), truth.yaw() + 5.0 * kDegree);
  const SixDofIcpResult r = SixDofIcp().Align(target, source, start.ToIsometry());
  const FourDofIcpResult r4 = FourDofIcp().Align(target, source, start);
  ASSERT_TRUE(r.ok()) << r.status.ToString();
  ASSERT_TRUE(r4.ok()) << r4.status.ToString();
  EXPECT_LT(FourDofTransform::TiltOf(r.T_a_b.linear()), 0.1 * kDegree);
  const FourDofTransform projected = FourDofTransform::ProjectIsometry(r.T_a_b);
  EXPECT_LT((projected.translation() - truth.translation()).norm(), 0.005);
  EXPECT_LT((projected.translation() - r4.T_a_b.translation()).norm(), 0.003);
  EXPECT_LT(std::abs(WrapAngle(projected.yaw() - r4.T_a_b.yaw())), 0.05 * kDegree);
  // x, y and yaw are known about as well (two more unknowns, slightly other pairs); z less well,
  // since a tilt about A's origin moves the clouds, metres away, up and down as well.
  for (const int i : {0, 1}) {
    EXPECT_GT(r.covariance(i, i), 0.5 * r4.covariance(i, i)) << i;
    EXPECT_LT(r.covariance(i, i), 2.0 * r4.covariance(i, i)) << i;
  }
  EXPECT_GT(r.covariance(2, 2), r4.covariance(2, 2));
  EXPECT_GT(r.covariance(5, 5), 0.5 * r4.covariance(3, 3));
  EXPECT_LT(r.covariance(5, 5), 2.0 * r4.covariance(3, 3));
}

// Over repeated noisy trials e^T Sigma^-1 e of a consistent 6-D covariance averages 6.
TEST(SixDofIcpTest, CovarianceIsConsistentOverNoisyTrials) {
  const Eigen::Isometry3d truth = TiltedTruth();
  std::mt19937_64 rng(23);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  double sum = 0.0;
  int used = 0;
  for (int t = 0; t < 30; ++t) {
    const std::vector<Eigen::Vector3d> scene_a = IcpTestScene(0.1, 0.5 + 0.5 * unit(rng));
    const std::vector<Eigen::Vector3d> scene_b = IcpTestScene(0.1, 0.5 + 0.5 * unit(rng));
    const std::vector<Eigen::Vector3d> target = IcpTestCloud(scene_a, -10.0, 2.0, Eigen::Isometry3d::Identity(), 0.01, rng());
    const std::vector<Eigen::Vector3d> source = IcpTestCloud(scene_b, -2.0, 10.0, truth.inverse(), 0.01, rng());
    const Eigen::Vector3d dt = 0.2 * DrawVector3(unit, rng);
    const Eigen::Vector3d dw = 2.0 * kDegree * DrawVector3(unit, rng);
    const SixDofIcpResult r = SixDofIcp().Align(target, source, Nudged(truth, dt, dw));
    EXPECT_TRUE(r.ok()) << r.status.ToString() << " trial " << t;
    if (!r.ok()) continue;
    const Eigen::Matrix<double, 6, 1> e = ErrorOf(r.T_a_b, truth);
    sum += e.dot(r.covariance.ldlt().solve(e));
    ++used;
  }
  const double nees = used > 0 ? sum / used : std::numeric_limits<double>::quiet_NaN();
  std::printf("6-DoF mean NEES over %d trials: %.2f (6 expected)\n", used, nees);
  // 30 trials: the mean of chi^2(6) has a standard deviation of 0.63; the model errors that lift
  // the 4-DoF figure (5 for 4) lift this one alike.
  EXPECT_GT(nees, 3.0);
  EXPECT_LT(nees, 10.5);
}

TEST(SixDofIcpTest, FlatPlaneIsDegenerate) {
  std::vector<Eigen::Vector3d> plane;
  SampleRect({-3.0, -3.0, 0.0}, {6.0, 0.0, 0.0}, {0.0, 6.0, 0.0}, 0.1, 0.5, &plane);
  const Eigen::Isometry3d truth = TiltedTruth();
  const std::vector<Eigen::Vector3d> target = IcpTestCloud(plane, -10.0, 10.0, Eigen::Isometry3d::Identity(), 0.01, 5);
  const std::vector<Eigen::Vector3d> source = IcpTestCloud(plane, -10.0, 10.0, truth.inverse(), 0.01, 6);
  const SixDofIcpResult r = SixDofIcp().Align(target, source, truth);
  EXPECT_FALSE(r.ok());
  EXPECT_TRUE(r.degenerate);
  EXPECT_EQ(r.status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status.message().find("roll, pitch, yaw"), std::string::npos) << r.status.message();
}

TEST(SixDofIcpTest, BadInputIsReported) {
  const std::vector<Eigen::Vector3d> scene = IcpTestScene(0.1, 0.5);
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(SixDofIcp().Align(scene, scene, bad).status.code(), StatusCode::kInvalidArgument);
  const std::vector<Eigen::Vector3d> empty;
  const SixDofIcpResult r = SixDofIcp().Align(empty, scene, Eigen::Isometry3d::Identity());
  EXPECT_EQ(r.status.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(r.status.message().find("target cloud is empty"), std::string::npos) << r.status.message();
}

}  // namespace
}  // namespace cairn
