#include "mapping/matching/six_dof_ransac.h"

#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

// A rotation far from gravity-aligned: the 4-DoF solver could not express it.
Eigen::Isometry3d FullTruth() {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(Eigen::Vector3d(0.4, -0.3, 1.1));
  T.translation() = Eigen::Vector3d(2.0, -1.0, 0.5);
  return T;
}

struct Pairs {
  std::vector<Eigen::Vector3d> source_b, target_a;
};

// `inliers` points of A with their counterparts in B, then `outliers` unrelated pairs.
Pairs MakePairs(const Eigen::Isometry3d& T_a_b, int inliers, int outliers, double noise, uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);
  const Eigen::Vector3d half_extent(5.0, 5.0, 1.0);
  Pairs c;
  for (int i = 0; i < inliers + outliers; ++i) {
    const Eigen::Vector3d a = DrawVector3(unit, rng).cwiseProduct(half_extent);
    Eigen::Vector3d b = T_a_b.inverse() * a;
    if (i >= inliers) b = T_a_b.inverse() * Eigen::Vector3d(DrawVector3(unit, rng).cwiseProduct(half_extent));
    c.target_a.push_back(a + noise * DrawVector3(gauss, rng));
    c.source_b.push_back(b + noise * DrawVector3(gauss, rng));
  }
  return c;
}

double RotationError(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd(a.linear() * b.linear().transpose()).angle();
}

TEST(SixDofRansacTest, MinimalSolverIsExactOnThreePoints) {
  const Eigen::Isometry3d truth = FullTruth();
  const Eigen::Vector3d target[3] = {{0.0, 0.0, 0.0}, {1.0, 0.2, 0.1}, {0.3, 1.2, -0.2}};
  const Eigen::Vector3d source[3] = {truth.inverse() * target[0], truth.inverse() * target[1],
                                     truth.inverse() * target[2]};
  const auto T = SixDofRansac().SolveThreePoint(source, target);
  ASSERT_TRUE(T.has_value());
  EXPECT_LT((T->translation() - truth.translation()).norm(), 1e-12);
  EXPECT_LT(RotationError(*T, truth), 1e-12);
}

TEST(SixDofRansacTest, DegenerateSamplesAreRejected) {
  const SixDofRansac ransac;
  const Eigen::Vector3d line[3] = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {2.0, 0.05, 0.0}};  // nearly collinear
  EXPECT_FALSE(ransac.SolveThreePoint(line, line).has_value());
  const Eigen::Vector3d close[3] = {{0.0, 0.0, 0.0}, {0.1, 0.0, 0.0}, {0.0, 1.0, 0.0}};  // two within 0.3 m
  EXPECT_FALSE(ransac.SolveThreePoint(close, close).has_value());
  const Eigen::Vector3d a[3] = {{0.0, 0.0, 0.0}, {1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}};
  const Eigen::Vector3d b[3] = {{0.0, 0.0, 0.0}, {1.5, 0.0, 0.0}, {0.0, 1.0, 0.0}};  // a side 0.5 m longer
  EXPECT_FALSE(ransac.SolveThreePoint(b, a).has_value());
  EXPECT_TRUE(ransac.SolveThreePoint(a, a).has_value());
}

TEST(SixDofRansacTest, RecoversAFullRotationFromSixtyPercentOutliers) {
  const Eigen::Isometry3d truth = FullTruth();
  const Pairs c = MakePairs(truth, 40, 60, 0.01, 3);
  const Expected<SixDofRansacResult> r = SixDofRansac().Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_LT((r->T_a_b.translation() - truth.translation()).norm(), 0.02);
  EXPECT_LT(RotationError(r->T_a_b, truth), 0.3 * kDegree);
  EXPECT_GE(r->inliers.size(), 38u);
  EXPECT_LE(r->inliers.size(), 42u);
  for (const size_t i : r->inliers) EXPECT_LT(i, 40u + 2u);
}

TEST(SixDofRansacTest, DeterministicForASeed) {
  const Pairs c = MakePairs(FullTruth(), 30, 70, 0.01, 4);
  const Expected<SixDofRansacResult> r1 = SixDofRansac().Estimate(c.source_b, c.target_a);
  const Expected<SixDofRansacResult> r2 = SixDofRansac().Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r1.ok() && r2.ok());
  EXPECT_EQ(r1->inliers, r2->inliers);
  EXPECT_EQ(r1->iterations, r2->iterations);
  EXPECT_TRUE(r1->T_a_b.matrix() == r2->T_a_b.matrix());
}

TEST(SixDofRansacTest, BadInputAndNoConsensusAreReported) {
  const Pairs c = MakePairs(FullTruth(), 2, 0, 0.0, 5);
  EXPECT_EQ(SixDofRansac().Estimate(c.source_b, c.target_a).status().code(), StatusCode::kFailedPrecondition);
  const Pairs d = MakePairs(FullTruth(), 10, 0, 0.0, 6);
  const std::vector<Eigen::Vector3d> shorter(d.source_b.begin(), d.source_b.end() - 1);
  EXPECT_EQ(SixDofRansac().Estimate(shorter, d.target_a).status().code(), StatusCode::kInvalidArgument);
  const Pairs noise = MakePairs(FullTruth(), 0, 60, 0.0, 7);
  FourDofRansacOptions strict;
  strict.min_inliers = 10;
  EXPECT_EQ(SixDofRansac(strict).Estimate(noise.source_b, noise.target_a).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace cairn
