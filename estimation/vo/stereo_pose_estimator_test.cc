// The pose core of the visual odometry on synthetic point pairs with known motion: exact
// recovery, robustness to outliers, refusal of degenerate input, and covariance consistency
// (NEES) under pixel noise.

#include "estimation/vo/stereo_pose_estimator.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"
#include "estimation/testing/vo_test_scene.h"
#include "stereo/stereo_error_model.h"

namespace cairn {
namespace {

RectifiedStereoCamera Camera() { return testing::VoTestScene::EurocLikeCamera(); }

StereoObservation Observe(const RectifiedStereoCamera& c, const Eigen::Vector3d& p) {
  return {c.f * p.x() / p.z() + c.cx, c.f * (p.x() - c.baseline) / p.z() + c.cx, c.f * p.y() / p.z() + c.cy};
}

Eigen::Isometry3d Motion(double tx, double ty, double tz, double rx, double ry, double rz) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(Eigen::Vector3d(rx, ry, rz));
  T.translation() = Eigen::Vector3d(tx, ty, tz);
  return T;
}

// Scene points visible in both frames, as observed (with pixel noise) and triangulated.
struct Pairs {
  std::vector<StereoPoint> kf, cur;
};

Pairs MakePairs(const RectifiedStereoCamera& cam, const Eigen::Isometry3d& T_kf_cur, int n, double noise_px,
                double sigma_px, std::mt19937_64& rng, double z_min = 1.5, double z_max = 6.0) {
  std::uniform_real_distribution<double> ux(0.0, cam.width), uy(0.0, cam.height), uz(z_min, z_max);
  std::normal_distribution<double> noise(0.0, noise_px);
  Pairs out;
  const Eigen::Isometry3d T_cur_kf = T_kf_cur.inverse();
  while (static_cast<int>(out.kf.size()) < n) {
    const double z = uz(rng);
    const double v = uy(rng), u = ux(rng);  // GCC's argument order, on every compiler
    const Eigen::Vector3d p_kf((u - cam.cx) * z / cam.f, (v - cam.cy) * z / cam.f, z);
    const Eigen::Vector3d p_cur = T_cur_kf * p_kf;
    if (p_cur.z() < 0.5) continue;
    StereoObservation a = Observe(cam, p_kf), b = Observe(cam, p_cur);
    for (StereoObservation* o : {&a, &b}) {
      o->u_left += noise(rng);
      o->u_right += noise(rng);
      o->v += noise(rng) / std::sqrt(2.0);  // the mean of two rows
    }
    StereoPoint pa, pb;
    if (!TriangulateStereo(cam, a, sigma_px, 0.5, &pa) || !TriangulateStereo(cam, b, sigma_px, 0.5, &pb)) continue;
    out.kf.push_back(pa);
    out.cur.push_back(pb);
  }
  return out;
}

Vector6d Error(const Eigen::Isometry3d& est, const Eigen::Isometry3d& truth) {
  Vector6d e;
  e.head<3>() = est.translation() - truth.translation();
  e.tail<3>() = so3::Log(Eigen::Matrix3d(truth.linear().transpose() * est.linear()));
  return e;
}

TEST(TriangulateStereoTest, CovarianceDiagonalIsThesisEquation52) {
  const RectifiedStereoCamera cam = Camera();
  const StereoErrorModel model(cam.f, cam.baseline, 0.5);
  for (const Eigen::Vector3d& p : {Eigen::Vector3d(0.3, -0.2, 2.0), Eigen::Vector3d(-1.0, 0.5, 5.0)}) {
    StereoPoint sp;
    ASSERT_TRUE(TriangulateStereo(cam, Observe(cam, p), 0.5, 0.5, &sp));
    EXPECT_LT((sp.p - p).norm(), 1e-12);
    const Eigen::Vector3d expected = model.PointError(p);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(std::sqrt(sp.cov(k, k)), expected[k], 1e-12 * (1.0 + expected[k]));
  }
  StereoPoint sp;
  EXPECT_FALSE(TriangulateStereo(cam, StereoObservation{100.0, 100.2, 50.0}, 0.5, 0.5, &sp));
  EXPECT_FALSE(TriangulateStereo(cam, StereoObservation{NAN, 100.2, 50.0}, 0.5, 0.5, &sp));
}

TEST(StereoPoseEstimatorTest, RecoversExactMotionDespiteOutliers) {
  const RectifiedStereoCamera cam = Camera();
  std::mt19937_64 rng(1);
  const Eigen::Isometry3d truth = Motion(0.12, -0.03, 0.25, 0.02, -0.08, 0.01);
  Pairs pairs = MakePairs(cam, truth, 200, 0.0, 0.3, rng);
  // 30 % gross outliers: current points moved by up to a metre.
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  for (size_t i = 0; i < pairs.cur.size(); i += 3) pairs.cur[i].p += DrawVector3(u, rng);
  VoOptions o;
  StereoPoseEstimator est(o);
  const PoseEstimate e = est.Estimate(pairs.kf, pairs.cur, 7);
  ASSERT_EQ(e.status, VoStatus::kOk) << VoStatusName(e.status) << " inliers " << e.inliers << " it " << e.ransac_iterations;
  const Vector6d err = Error(e.T_kf_cur, truth);
  EXPECT_LT(err.head<3>().norm(), 1e-9);
  EXPECT_LT(err.tail<3>().norm(), 1e-9);
  EXPECT_GE(e.inliers, 130);
  EXPECT_LE(e.inliers, 134);  // 133 clean pairs; a moved one may land by chance inside the gate
  // Same seed, same answer.
  const PoseEstimate again = est.Estimate(pairs.kf, pairs.cur, 7);
  EXPECT_EQ(again.T_kf_cur.matrix(), e.T_kf_cur.matrix());
}

TEST(StereoPoseEstimatorTest, ReportsTooFewAndDegenerateInput) {
  const RectifiedStereoCamera cam = Camera();
  std::mt19937_64 rng(2);
  VoOptions o;
  StereoPoseEstimator est(o);
  Pairs few = MakePairs(cam, Eigen::Isometry3d::Identity(), 5, 0.0, 0.3, rng);
  EXPECT_EQ(est.Estimate(few.kf, few.cur, 1).status, VoStatus::kTooFewInliers);
  // All points within 2 mm of one vertical line 4 m away (a pole): the rotation about it is
  // not determined.
  Pairs pole;
  std::uniform_real_distribution<double> off(-0.002, 0.002), along(-1.0, 1.0);
  for (int i = 0; i < 40; ++i) {
    const double dz = off(rng), y = along(rng), dx = off(rng);  // GCC's argument order
    const Eigen::Vector3d p(0.5 + dx, y, 4.0 + dz);
    StereoPoint sp;
    ASSERT_TRUE(TriangulateStereo(cam, Observe(cam, p), 0.3, 0.5, &sp));
    pole.kf.push_back(sp);
    pole.cur.push_back(sp);
  }
  const PoseEstimate pe = est.Estimate(pole.kf, pole.cur, 1);
  EXPECT_EQ(pe.status, VoStatus::kDegenerate) << VoStatusName(pe.status);
  // Random, unrelated point sets: no consistent motion.
  Pairs a = MakePairs(cam, Eigen::Isometry3d::Identity(), 60, 0.0, 0.3, rng);
  Pairs b = MakePairs(cam, Eigen::Isometry3d::Identity(), 60, 0.0, 0.3, rng);
  EXPECT_EQ(est.Estimate(a.kf, b.cur, 1).status, VoStatus::kTooFewInliers);
}

// Normalized estimation error squared over many noisy trials: with pixel noise of the assumed
// sigma the 6-DoF NEES averages 6. Bounds: the 99.9 % interval of the mean of 400 chi-square(6)
// draws is 6 +- 0.57; above it 25 % are allowed because the covariance is first order in the
// pixel noise while depth is 1/disparity (points up to 6 m have 8 px disparity, so the noise is
// 5 % of it) and is evaluated at the noisy points. Measured: 7.1 (slightly overconfident).
TEST(StereoPoseEstimatorTest, CovarianceIsConsistent) {
  const RectifiedStereoCamera cam = Camera();
  std::mt19937_64 rng(3);
  VoOptions o;
  o.pixel_sigma = 0.3;
  StereoPoseEstimator est(o);
  const int kTrials = 400;
  double nees_sum = 0.0;
  int ok = 0;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Eigen::Vector3d w = 0.05 * DrawVector3(u, rng);
    const Eigen::Vector3d t = Eigen::Vector3d(0.1, 0.1, 0.3).cwiseProduct(DrawVector3(u, rng));
    const Eigen::Isometry3d truth = Motion(t.x(), t.y(), t.z(), w.x(), w.y(), w.z());
    const Pairs pairs = MakePairs(cam, truth, 80, o.pixel_sigma, o.pixel_sigma, rng);
    const PoseEstimate e = est.Estimate(pairs.kf, pairs.cur, static_cast<uint64_t>(trial));
    if (e.status != VoStatus::kOk) {
      std::printf("trial %d: %s, %d inliers\n", trial, VoStatusName(e.status), e.inliers);
      continue;
    }
    const Vector6d err = Error(e.T_kf_cur, truth);
    nees_sum += err.dot(e.covariance.ldlt().solve(err));
    ++ok;
  }
  ASSERT_GE(ok, kTrials - 2);
  const double nees = nees_sum / ok;
  std::printf("mean NEES %.3f over %d trials (6 expected)\n", nees, ok);
  EXPECT_GT(nees, 6.0 - 0.57);
  EXPECT_LT(nees, 1.25 * (6.0 + 0.57));
}

}  // namespace
}  // namespace cairn
