// The two-frame bundle adjustment on synthetic stereo observations with known motion: exact
// recovery from a perturbed start, the information against Monte Carlo errors (NEES), and
// refusal of unusable input.

#include "estimation/vo/two_frame_bundle_adjuster.h"

#include <cmath>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"
#include "estimation/testing/stereo_matches.h"
#include "estimation/testing/vo_test_scene.h"

namespace cairn {
namespace {

// n matches 2-12 m ahead of the keyframe, all adjusted.
struct Scene : testing::StereoMatches {
  std::vector<uint8_t> mask;
};

Scene MakeScene(const RectifiedStereoCamera& cam, const Eigen::Isometry3d& T_kf_cur, int n, double noise_px,
                std::mt19937_64& rng) {
  Scene s;
  static_cast<testing::StereoMatches&>(s) =
      testing::MakeStereoMatches(cam, T_kf_cur, n, noise_px, 0.3, rng, 2.0, 12.0, 1.0);
  s.mask.assign(s.kf.size(), 1);
  return s;
}

Eigen::Isometry3d Motion(const Eigen::Vector3d& t, const Eigen::Vector3d& w) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(w);
  T.translation() = t;
  return T;
}

Vector6d Error(const BundleResult& r, const Eigen::Isometry3d& truth) {
  Vector6d e;
  e.head<3>() = r.t - truth.translation();
  e.tail<3>() = so3::Log(Eigen::Matrix3d(truth.linear().transpose() * r.R));
  return e;
}

TEST(TwoFrameBundleAdjusterTest, RecoversExactMotionFromAPerturbedStart) {
  const RectifiedStereoCamera cam = testing::VoTestScene::EurocLikeCamera();
  std::mt19937_64 rng(1);
  const Eigen::Isometry3d truth = Motion({0.2, -0.05, 0.4}, {0.03, -0.06, 0.02});
  Scene s = MakeScene(cam, truth, 100, 0.0, rng);
  s.mask[7] = 0;
  s.cur_seen[7].u_left += 40.0;  // masked out: must not matter
  s.cur_seen[8].v = NAN;         // in the mask but unusable: left out, and said so
  TwoFrameBundleAdjuster adjuster(cam, 0.3);
  const Eigen::Matrix3d R0 = truth.linear() * so3::Exp(Eigen::Vector3d(0.01, 0.02, -0.015));
  const Eigen::Vector3d t0 = truth.translation() + Eigen::Vector3d(0.03, -0.02, 0.05);
  BundleResult r;
  ASSERT_TRUE(adjuster.Adjust(s.kf_seen, s.cur_seen, s.kf, s.mask, R0, t0, 20, &r));
  const Vector6d e = Error(r, truth);
  EXPECT_LT(e.head<3>().norm(), 1e-9);
  EXPECT_LT(e.tail<3>().norm(), 1e-9);
  EXPECT_EQ(r.points, 98);
  EXPECT_LT(r.chi2, 1e-12);
  EXPECT_EQ(adjuster.point_chi2()[7], 0.0);
  EXPECT_TRUE(std::isinf(adjuster.point_chi2()[8]));
  // The information is symmetric positive definite.
  EXPECT_LT((r.information - r.information.transpose()).norm(), 1e-9 * r.information.norm());
  EXPECT_GT(r.information.ldlt().vectorD().minCoeff(), 0.0);
}

// With pixel noise of the assumed sigma, the error against the inverse information averages
// chi-square(6): 6, with the 99.9 % interval of a mean of 400 draws +- 0.57. A margin of 10 % is
// allowed above it because the information is first order at the estimate.
TEST(TwoFrameBundleAdjusterTest, InformationMatchesTheErrors) {
  const RectifiedStereoCamera cam = testing::VoTestScene::EurocLikeCamera();
  std::mt19937_64 rng(5);
  TwoFrameBundleAdjuster adjuster(cam, 0.3);
  const int kTrials = 400;
  double nees = 0.0;
  for (int trial = 0; trial < kTrials; ++trial) {
    std::uniform_real_distribution<double> u(-1.0, 1.0);
    const Eigen::Vector3d w = 0.05 * DrawVector3(u, rng);
    const Eigen::Vector3d t = Eigen::Vector3d(0.1, 0.1, 0.3).cwiseProduct(DrawVector3(u, rng));
    const Eigen::Isometry3d truth = Motion(t, w);
    const Scene s = MakeScene(cam, truth, 60, 0.3, rng);
    BundleResult r;
    ASSERT_TRUE(
        adjuster.Adjust(s.kf_seen, s.cur_seen, s.kf, s.mask, truth.linear(), truth.translation(), 20, &r));
    const Vector6d e = Error(r, truth);
    nees += e.dot(r.information * e);
  }
  nees /= kTrials;
  std::printf("mean NEES %.3f over %d trials (6 expected)\n", nees, kTrials);
  EXPECT_GT(nees, 6.0 - 0.57);
  EXPECT_LT(nees, 1.1 * (6.0 + 0.57));
}

TEST(TwoFrameBundleAdjusterTest, RefusesUnusableInput) {
  const RectifiedStereoCamera cam = testing::VoTestScene::EurocLikeCamera();
  std::mt19937_64 rng(2);
  const Eigen::Isometry3d truth = Motion({0.1, 0.0, 0.2}, {0.0, 0.02, 0.0});
  Scene s = MakeScene(cam, truth, 10, 0.0, rng);
  TwoFrameBundleAdjuster adjuster(cam, 0.3);
  BundleResult r;
  r.points = -1;
  // Two usable pairs: a NaN pixel and the mask take out the rest.
  for (size_t i = 2; i < s.mask.size(); ++i) s.mask[i] = 0;
  s.mask[9] = 1;
  s.kf_seen[9].v = NAN;
  EXPECT_FALSE(
      adjuster.Adjust(s.kf_seen, s.cur_seen, s.kf, s.mask, truth.linear(), truth.translation(), 10, &r));
  EXPECT_EQ(r.points, -1);
  // A start that puts every point behind the current camera.
  Scene all = MakeScene(cam, truth, 10, 0.0, rng);
  EXPECT_FALSE(adjuster.Adjust(all.kf_seen, all.cur_seen, all.kf, all.mask, truth.linear(),
                               Eigen::Vector3d(0.0, 0.0, 50.0), 10, &r));
  // No camera.
  TwoFrameBundleAdjuster blind(RectifiedStereoCamera{}, 0.3);
  EXPECT_FALSE(
      blind.Adjust(all.kf_seen, all.cur_seen, all.kf, all.mask, truth.linear(), truth.translation(), 10, &r));
}

}  // namespace
}  // namespace cairn
