#include "mapping/matching/four_dof_ransac.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "estimation/math/ordered_draws.h"

namespace cairn {
namespace {

// Keypoint-like correspondences between two gravity-aligned submaps: `inliers` points in A's
// frame with their counterparts in B (moved by T_a_b^-1, plus noise), then `outliers` pairs of
// unrelated points in the same volumes.
struct Correspondences {
  std::vector<Eigen::Vector3d> source_b;
  std::vector<Eigen::Vector3d> target_a;
  std::vector<bool> is_inlier;
};

Correspondences MakeCorrespondences(const FourDofTransform& T_a_b, int inliers, int outliers, double noise,
                                    uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  std::normal_distribution<double> gauss(0.0, 1.0);  // scaled: a zero standard deviation is not allowed
  const Eigen::Vector3d half_extent(5.0, 5.0, 1.0);
  const FourDofTransform T_b_a = T_a_b.inverse();
  Correspondences c;
  for (int i = 0; i < inliers + outliers; ++i) {
    const Eigen::Vector3d a = DrawVector3(unit, rng).cwiseProduct(half_extent);
    Eigen::Vector3d b = T_b_a * a;
    if (i >= inliers) b = T_b_a * Eigen::Vector3d(DrawVector3(unit, rng).cwiseProduct(half_extent));
    c.target_a.push_back(a + noise * DrawVector3(gauss, rng));
    c.source_b.push_back(b + noise * DrawVector3(gauss, rng));
    c.is_inlier.push_back(i < inliers);
  }
  // Interleave inliers and outliers so that the order says nothing.
  std::vector<size_t> order(c.is_inlier.size());
  for (size_t i = 0; i < order.size(); ++i) order[i] = (i * 37) % order.size();
  Correspondences shuffled;
  for (const size_t i : order) {
    shuffled.source_b.push_back(c.source_b[i]);
    shuffled.target_a.push_back(c.target_a[i]);
    shuffled.is_inlier.push_back(c.is_inlier[i]);
  }
  return shuffled;
}

double YawError(const FourDofTransform& a, const FourDofTransform& b) {
  return std::abs(WrapAngle(a.yaw() - b.yaw()));
}

TEST(FourDofRansacTest, MinimalSolverIsTheThesisConstruction) {
  // Eqs. 6.5 to 6.7 written out with matrices: R_i has the columns d'_i/|d'_i|, (d'_i x z)/|.|, z.
  const auto frame = [](const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
    const Eigen::Vector3d z = Eigen::Vector3d::UnitZ();
    Eigen::Vector3d d = q - p;
    d -= d.dot(z) * z;
    Eigen::Matrix3d R;
    R.col(0) = d.normalized();
    R.col(1) = d.cross(z).normalized();
    R.col(2) = z;
    return R;
  };
  const FourDofTransform truth(2.0, -1.0, 0.3, 2.7);
  const Eigen::Vector3d a0(1.0, 2.0, 0.5), a1(-0.5, 0.4, 1.2);
  const Eigen::Vector3d b0 = truth.inverse() * a0, b1 = truth.inverse() * a1;
  const std::optional<FourDofTransform> T = FourDofRansac().SolveTwoPoint(b0, b1, a0, a1);
  ASSERT_TRUE(T.has_value());
  const Eigen::Matrix3d R = frame(a0, a1) * frame(b0, b1).transpose();
  const Eigen::Vector3d t = 0.5 * (a0 + a1) - R * 0.5 * (b0 + b1);
  EXPECT_LT((T->rotation() - R).norm(), 1e-12);
  EXPECT_LT((T->translation() - t).norm(), 1e-12);
  EXPECT_LT((T->ToVector() - truth.ToVector()).norm(), 1e-12);
  EXPECT_LT((*T * b0 - a0).norm(), 1e-12);
  EXPECT_LT((*T * b1 - a1).norm(), 1e-12);
}

TEST(FourDofRansacTest, DegeneratePairsAreRejected) {
  const FourDofRansac ransac;  // 0.3 m separation, 0.1 m length tolerance
  const Eigen::Vector3d a0(0.0, 0.0, 0.0);
  // Stacked vertically: no horizontal direction.
  EXPECT_FALSE(ransac.SolveTwoPoint({1, 1, 0}, {1.05, 1, 1}, a0, {0.05, 0, 1}).has_value());
  // Horizontal lengths 1.0 and 1.3 m.
  EXPECT_FALSE(ransac.SolveTwoPoint({0, 0, 0}, {1, 0, 0}, a0, {0, 1.3, 0}).has_value());
  // Height differences 0 and 0.4 m.
  EXPECT_FALSE(ransac.SolveTwoPoint({0, 0, 0}, {1, 0, 0}, a0, {0, 1, 0.4}).has_value());
  // Within the tolerances it solves.
  EXPECT_TRUE(ransac.SolveTwoPoint({0, 0, 0}, {1, 0, 0}, a0, {0, 1.05, 0.05}).has_value());
}

TEST(FourDofRansacTest, RecoversTheTransformFromSixtyPercentOutliers) {
  const FourDofTransform truth(3.0, -2.0, 0.4, -2.2);
  const Correspondences c = MakeCorrespondences(truth, 40, 60, 0.01, 7);
  FourDofRansacOptions o;
  o.inlier_threshold = 0.08;  // 5.7 sigma (0.014 m per axis) of an inlier's error: none is lost by chance
  const Expected<FourDofRansacResult> r = FourDofRansac(o).Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_LT((r->T_a_b.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(YawError(r->T_a_b, truth), 0.002);
  size_t true_found = 0;
  for (const size_t i : r->inliers) true_found += c.is_inlier[i] ? 1 : 0;
  EXPECT_EQ(true_found, 40u);
  EXPECT_EQ(r->inliers.size(), 40u);
  EXPECT_TRUE(std::is_sorted(r->inliers.begin(), r->inliers.end()));
  EXPECT_LT(r->inlier_rms, 0.03);
  EXPECT_LT(r->iterations, o.max_iterations);  // the adaptive stop ended it
}

TEST(FourDofRansacTest, RecoversTheTransformFromSeventyFivePercentOutliers) {
  const FourDofTransform truth(-1.0, 4.0, -0.2, 0.4);
  const Correspondences c = MakeCorrespondences(truth, 30, 90, 0.01, 11);
  FourDofRansacOptions o;
  o.inlier_threshold = 0.08;
  o.seed = 3;
  const Expected<FourDofRansacResult> r = FourDofRansac(o).Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_LT((r->T_a_b.translation() - truth.translation()).norm(), 0.01);
  EXPECT_LT(YawError(r->T_a_b, truth), 0.002);
  EXPECT_EQ(r->inliers.size(), 30u);
}

TEST(FourDofRansacTest, DeterministicForASeed) {
  const FourDofTransform truth(0.5, 0.5, 0.0, 1.0);
  const Correspondences c = MakeCorrespondences(truth, 20, 40, 0.01, 5);
  FourDofRansacOptions o;
  o.inlier_threshold = 0.08;
  o.seed = 42;
  const Expected<FourDofRansacResult> r1 = FourDofRansac(o).Estimate(c.source_b, c.target_a);
  const Expected<FourDofRansacResult> r2 = FourDofRansac(o).Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r1.ok() && r2.ok());
  EXPECT_EQ(r1->T_a_b.ToVector(), r2->T_a_b.ToVector());  // bit for bit
  EXPECT_EQ(r1->inliers, r2->inliers);
  EXPECT_EQ(r1->iterations, r2->iterations);
  // Another seed draws other samples but finds the same consensus.
  o.seed = 43;
  const Expected<FourDofRansacResult> r3 = FourDofRansac(o).Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r3.ok());
  EXPECT_EQ(r3->inliers, r1->inliers);
  EXPECT_LT((r3->T_a_b.ToVector() - r1->T_a_b.ToVector()).norm(), 1e-6);
}

TEST(FourDofRansacTest, IterationsAreBoundedAndStopEarlyOnCleanData) {
  const FourDofTransform truth(1.0, 2.0, 3.0, 0.1);
  const Correspondences clean = MakeCorrespondences(truth, 50, 0, 0.0, 2);
  const Expected<FourDofRansacResult> r = FourDofRansac().Estimate(clean.source_b, clean.target_a);
  ASSERT_TRUE(r.ok());
  EXPECT_LE(r->iterations, 3);  // the first good sample makes one more unnecessary
  EXPECT_EQ(r->inliers.size(), 50u);
  EXPECT_LT((r->T_a_b.ToVector() - truth.ToVector()).norm(), 1e-9);

  const Correspondences noisy = MakeCorrespondences(truth, 10, 90, 0.01, 3);
  FourDofRansacOptions o;
  o.max_iterations = 7;
  const Expected<FourDofRansacResult> bounded = FourDofRansac(o).Estimate(noisy.source_b, noisy.target_a);
  if (bounded.ok()) {
    EXPECT_EQ(bounded->iterations, 7);
  } else {
    EXPECT_EQ(bounded.status().code(), StatusCode::kNotFound);
  }
}

TEST(FourDofRansacTest, TooFewCorrespondencesAndBadInputAreReported) {
  const FourDofRansac ransac;
  const std::vector<Eigen::Vector3d> none;
  const Expected<FourDofRansacResult> empty = ransac.Estimate(none, none);
  ASSERT_FALSE(empty.ok());
  EXPECT_EQ(empty.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(empty.status().message().find("too few correspondences"), std::string::npos);
  const std::vector<Eigen::Vector3d> two = {{0, 0, 0}, {1, 0, 0}};
  EXPECT_EQ(ransac.Estimate(two, two).status().code(), StatusCode::kFailedPrecondition);  // min_inliers 3
  const std::vector<Eigen::Vector3d> three = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  EXPECT_EQ(ransac.Estimate(two, three).status().code(), StatusCode::kInvalidArgument);
  FourDofRansacOptions bad;
  bad.inlier_threshold = 0.0;
  EXPECT_EQ(FourDofRansac(bad).Estimate(three, three).status().code(), StatusCode::kInvalidArgument);
}

TEST(FourDofRansacTest, NonFiniteCorrespondencesAreSkipped) {
  const FourDofTransform truth(1.0, -1.0, 0.2, -0.7);
  Correspondences c = MakeCorrespondences(truth, 20, 10, 0.005, 9);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  c.source_b[3] = {nan, 0.0, 0.0};
  c.target_a[8] = {0.0, std::numeric_limits<double>::infinity(), 0.0};
  const Expected<FourDofRansacResult> r = FourDofRansac().Estimate(c.source_b, c.target_a);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->skipped_non_finite, 2u);
  for (const size_t i : r->inliers) {
    EXPECT_NE(i, 3u);
    EXPECT_NE(i, 8u);
  }
  EXPECT_LT((r->T_a_b.translation() - truth.translation()).norm(), 0.01);
}

TEST(FourDofRansacTest, NoConsensusIsReported) {
  // Unrelated points: no hypothesis explains five of them.
  const Correspondences random = MakeCorrespondences(FourDofTransform(), 0, 100, 0.0, 4);
  FourDofRansacOptions o;
  o.min_inliers = 5;
  o.inlier_threshold = 0.05;
  const Expected<FourDofRansacResult> r = FourDofRansac(o).Estimate(random.source_b, random.target_a);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.status().code(), StatusCode::kNotFound);
  EXPECT_NE(r.status().message().find("no consensus"), std::string::npos) << r.status().message();

  // Every point on one vertical line: every sample is degenerate.
  std::vector<Eigen::Vector3d> line;
  for (int i = 0; i < 10; ++i) line.emplace_back(1.0, 2.0, 0.1 * i);
  const Expected<FourDofRansacResult> d = FourDofRansac().Estimate(line, line);
  ASSERT_FALSE(d.ok());
  EXPECT_EQ(d.status().code(), StatusCode::kNotFound);
  EXPECT_NE(d.status().message().find("degenerate"), std::string::npos) << d.status().message();
}

}  // namespace
}  // namespace cairn
