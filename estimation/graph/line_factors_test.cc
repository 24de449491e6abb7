#include "estimation/graph/line_factors.h"

#include <cmath>
#include <cstdio>
#include <random>

#include <gtest/gtest.h>

#include "estimation/graph/pose_factors.h"
#include "estimation/graph/slam_graph.h"
#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"
#include "estimation/math/tangent_axes.h"

namespace cairn {
namespace {

Pose3 LineTestPose(double x, double y, double z, double yaw) {
  return {Eigen::Vector3d(x, y, z), so3::ExpQuaternion(Eigen::Vector3d(0.0, 0.0, yaw))};
}

// A world line (point p_w, direction d_w) as the submap at T_w_s measures it: point and direction.
struct LineSeen {
  Eigen::Vector3d c, d;
};

LineSeen LineSeenIn(const Pose3& T_w_s, const Eigen::Vector3d& p_w, const Eigen::Vector3d& d_w) {
  return {T_w_s.R().transpose() * (p_w - T_w_s.t), T_w_s.R().transpose() * d_w.normalized()};
}

// The pose rotated by `angle` about the world axis `axis` through the world point `pivot`.
Pose3 RotatedAbout(const Pose3& T, const Eigen::Vector3d& axis, double angle, const Eigen::Vector3d& pivot) {
  const Eigen::Quaterniond r(Eigen::AngleAxisd(angle, axis.normalized()));
  return {pivot + r * (T.t - pivot), (r * T.q).normalized()};
}

TEST(LineFactorsTest, ManifoldMinusUndoesPlusAndMovesTheLineAcross) {
  const auto manifold = MakeLineLandmarkManifold();
  ASSERT_EQ(manifold->AmbientSize(), 7);
  ASSERT_EQ(manifold->TangentSize(), 4);
  const Pose3 x = LineLandmarkFrame(Eigen::Vector3d(0.6, 0.8, 0.3), Eigen::Vector3d(1.0, 2.0, 0.5));
  double xb[7], yb[7], back[4];
  PoseToBlock(x, xb);
  const double delta[4] = {0.05, -0.02, 0.3, -0.2};
  ASSERT_TRUE(manifold->Plus(xb, delta, yb));
  ASSERT_TRUE(manifold->Minus(yb, xb, back));
  for (int i = 0; i < 4; ++i) EXPECT_NEAR(back[i], delta[i], 1e-12);
  EXPECT_NEAR(Eigen::Vector4d(yb[3], yb[4], yb[5], yb[6]).norm(), 1.0, 1e-12);
  // The step moves the line perpendicular to itself, along the frame's x and y.
  const Pose3 y = BlockToPose(yb);
  const Eigen::Matrix3d R = x.R();
  EXPECT_NEAR((y.t - x.t).dot(R.col(2)), 0.0, 1e-12);
  EXPECT_LT((y.t - x.t - 0.3 * R.col(0) + 0.2 * R.col(1)).norm(), 1e-12);
  // And tilts its direction about the frame's own x and y axes.
  const Eigen::Vector3d tilted = R * so3::Exp(Eigen::Vector3d(0.05, -0.02, 0.0)) * Eigen::Vector3d::UnitZ();
  EXPECT_LT((y.R().col(2) - tilted).norm(), 1e-12);
}

TEST(LineFactorsTest, FrameHasTheDirectionAsZ) {
  const Eigen::Vector3d d(0.0, 3.0, 4.0), p(1.0, -1.0, 2.0);
  const Pose3 f = LineLandmarkFrame(d, p);
  EXPECT_LT((f.R().col(2) - d.normalized()).norm(), 1e-12);
  EXPECT_LT((f.t - p).norm(), 1e-15);
  Eigen::Vector3d u, v;
  TangentAxes(Eigen::Vector3d(d.normalized()), &u, &v);
  EXPECT_LT((f.R().col(0) - u).norm(), 1e-12);
  EXPECT_LT((f.R().col(1) - v).norm(), 1e-12);
}

TEST(LineFactorsTest, ResidualVanishesAtTheTruthForAnyFrameOfTheLine) {
  const Pose3 T_w_s = LineTestPose(2.0, -1.0, 0.2, 0.4);
  const Eigen::Vector3d d_w = Eigen::Vector3d(1.0, 0.3, 0.2).normalized(), p_w(3.0, 4.0, 1.0);
  const LineSeen z = LineSeenIn(T_w_s, p_w, d_w);
  const LineObservationResidual r(z.c, z.d, Eigen::Matrix4d::Identity());
  // Any point of the line, any rotation about it, either direction: the same landmark.
  const Pose3 l = LineLandmarkFrame(d_w, p_w + 5.0 * d_w);
  EXPECT_LT(r.Error(T_w_s, l).norm(), 1e-12);
  const Pose3 spun{l.t, l.q * Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()))};
  EXPECT_LT(r.Error(T_w_s, spun).norm(), 1e-12);
  const Pose3 reversed = LineLandmarkFrame(-d_w, p_w - 2.0 * d_w);
  EXPECT_LT(r.Error(T_w_s, reversed).norm(), 1e-12);
  // Away from the truth too, the reverse has the same error.
  const Pose3 off =
      RotatedAbout(Pose3{l.t + Eigen::Vector3d(0.1, -0.2, 0.05), l.q}, Eigen::Vector3d(1, 2, 3), 0.03, p_w);
  const Pose3 off_reversed{off.t,
                           off.q * Eigen::Quaterniond(Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitX()))};
  EXPECT_GT(r.Error(T_w_s, off).norm(), 0.01);
  EXPECT_LT((r.Error(T_w_s, off) - r.Error(T_w_s, off_reversed)).norm(), 1e-12);
}

TEST(LineFactorsTest, ResidualMeasuresShiftAndTiltInTheirComponents) {
  const Pose3 T_w_s = LineTestPose(2.0, -1.0, 0.2, 0.4);
  const Eigen::Vector3d d_w = Eigen::Vector3d(1.0, 0.3, 0.2).normalized(), p_w(3.0, 4.0, 1.0);
  const LineSeen z = LineSeenIn(T_w_s, p_w, d_w);
  const LineObservationResidual r(z.c, z.d, Eigen::Matrix4d::Identity());
  Eigen::Vector3d u, w;
  TangentAxes(z.d, &u, &w);
  const Eigen::Vector3d u_w = T_w_s.R() * u, w_w = T_w_s.R() * w;
  const Pose3 l = LineLandmarkFrame(d_w, p_w + 1.5 * d_w);
  // 0.1 m along u: the first offset component only.
  const Eigen::Vector4d shifted = r.Error(T_w_s, Pose3{l.t + 0.1 * u_w, l.q});
  EXPECT_LT((shifted - Eigen::Vector4d(0.0, 0.0, 0.1, 0.0)).norm(), 1e-12);
  // 0.02 rad about w through the observed point: the direction turns towards u (w x d = u).
  const Eigen::Vector4d tilted = r.Error(T_w_s, RotatedAbout(l, w_w, 0.02, p_w));
  EXPECT_LT((tilted - Eigen::Vector4d(std::sin(0.02), 0.0, 0.0, 0.0)).norm(), 1e-12);
  // And about u: towards -w.
  const Eigen::Vector4d tilted_u = r.Error(T_w_s, RotatedAbout(l, u_w, 0.02, p_w));
  EXPECT_LT((tilted_u - Eigen::Vector4d(0.0, -std::sin(0.02), 0.0, 0.0)).norm(), 1e-12);
}

// Monte Carlo consistency: one line landmark seen from 3 to 5 known submaps, each observation drawn
// from the stated covariance; the landmark's error against the solver's own covariance (NEES of
// 4 dimensions) in the estimate's tangent.
TEST(LineFactorsTest, LandmarkCovarianceIsConsistent) {
  const Eigen::Vector3d d_w = Eigen::Vector3d(1.0, 0.3, 0.2).normalized(), p_w(4.0, 2.0, 1.0);
  const std::vector<Pose3> submaps = {LineTestPose(0.0, 0.0, 0.0, 0.0), LineTestPose(2.0, -1.0, 0.1, 0.5),
                                      LineTestPose(5.0, -2.0, 0.2, 1.2), LineTestPose(7.0, 0.5, -0.1, 2.0),
                                      LineTestPose(3.0, 5.0, 0.3, -1.5)};
  const double sigma_r = 0.01, sigma_t = 0.02;  // rad, m
  const Eigen::Vector4d sigmas(sigma_r, sigma_r, sigma_t, sigma_t);
  const Eigen::Matrix4d information = sigmas.cwiseAbs2().cwiseInverse().asDiagonal();
  std::mt19937 rng(1);
  std::normal_distribution<double> n(0.0, 1.0);
  const int runs = 100;
  double nees = 0.0;
  for (int run = 0; run < runs; ++run) {
    double submap_blocks[5][7], landmark[7];
    ceres::Problem problem;
    const int seen = 3 + run % 3;
    for (int k = 0; k < seen; ++k) {
      // Each sees another stretch; every other one has the edge the other way round.
      const double s = -2.0 + 1.3 * k;
      LineSeen z = LineSeenIn(submaps[static_cast<size_t>(k)], p_w + s * d_w, (k % 2 ? -1.0 : 1.0) * d_w);
      Eigen::Vector3d u, w;
      TangentAxes(z.d, &u, &w);
      // Direction error along u and w, then the offset along u and w (draws in a fixed order).
      Eigen::Vector4d e;
      e.head<2>() = DrawVector2(n, rng);
      e.tail<2>() = DrawVector2(n, rng);
      e = sigmas.cwiseProduct(e);
      z.d = (z.d + e[0] * u + e[1] * w).normalized();
      z.c += e[2] * u + e[3] * w;
      PoseToBlock(submaps[static_cast<size_t>(k)], submap_blocks[k]);
      problem.AddResidualBlock(LineObservationResidual::Create(z.c, z.d, information), nullptr,
                               submap_blocks[k], landmark);
      problem.SetParameterBlockConstant(submap_blocks[k]);
    }
    // Start from a perturbed truth: another point, spin and a step off the line.
    const Pose3 start = LineLandmarkFrame(d_w, p_w + 0.7 * d_w);
    double start_block[7];
    PoseToBlock(
        Pose3{start.t, start.q * Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()))},
        start_block);
    Eigen::Vector4d step;
    step.head<2>() = 0.05 * DrawVector2(n, rng);
    step.tail<2>() = 0.1 * DrawVector2(n, rng);
    const auto manifold = MakeLineLandmarkManifold();
    ASSERT_TRUE(manifold->Plus(start_block, step.data(), landmark));
    problem.SetManifold(landmark, MakeLineLandmarkManifold().release());

    ceres::Solver::Options options;
    options.linear_solver_type = ceres::DENSE_QR;
    options.function_tolerance = options.gradient_tolerance = options.parameter_tolerance = 1e-14;
    ceres::Solver::Summary summary;
    ceres::Solve(options, &problem, &summary);
    ASSERT_TRUE(summary.IsSolutionUsable()) << summary.BriefReport();

    ceres::Covariance::Options cov_options;
    cov_options.algorithm_type = ceres::DENSE_SVD;
    ceres::Covariance covariance(cov_options);
    const std::vector<std::pair<const double*, const double*>> blocks = {{landmark, landmark}};
    ASSERT_TRUE(covariance.Compute(blocks, &problem));
    Eigen::Matrix<double, 4, 4, Eigen::RowMajor> cov;
    ASSERT_TRUE(covariance.GetCovarianceBlockInTangentSpace(landmark, landmark, cov.data()));

    // The truth in the frame nearest the estimate (its direction turned the least way, its origin
    // the truth's point closest to the estimate's), so that Minus gives the line's own error.
    const Pose3 est = BlockToPose(landmark);
    const Eigen::Vector3d v_e = est.R().col(2);
    const Eigen::Vector3d v_t = v_e.dot(d_w) < 0.0 ? Eigen::Vector3d(-d_w) : d_w;
    const Pose3 truth{p_w + (est.t - p_w).dot(v_t) * v_t,
                      (Eigen::Quaterniond::FromTwoVectors(v_e, v_t) * est.q).normalized()};
    double truth_block[7];
    PoseToBlock(truth, truth_block);
    Eigen::Vector4d err;
    ASSERT_TRUE(manifold->Minus(truth_block, landmark, err.data()));
    nees += err.dot(cov.inverse() * err) / runs;
  }
  // 95 % band of the mean of 100 chi2(4) draws: 4 -+ 1.96 sqrt(8 / 100).
  const double half_band = 1.96 * std::sqrt(8.0 / runs);
  std::printf(
      "[ lines] mean NEES of the landmark over %d runs: %.2f (4 degrees of freedom, band %.2f-%.2f)\n", runs,
      nees, 4.0 - half_band, 4.0 + half_band);
  EXPECT_GT(nees, 4.0 - half_band);
  EXPECT_LT(nees, 4.0 + half_band);
}

SlamFactor LineObservationFactor(uint64_t s, uint64_t l, const Pose3& T_w_s, const Eigen::Vector3d& p_w,
                                 const Eigen::Vector3d& d_w, double sigma) {
  const LineSeen z = LineSeenIn(T_w_s, p_w, d_w);
  SlamFactor f;
  f.kind = FactorKind::kLineObservation;
  f.a = s;
  f.b = l;
  f.line_point = z.c;
  f.line_direction = z.d;
  f.line_information = Eigen::Matrix4d::Identity() / (sigma * sigma);
  f.z = LineLandmarkFrame(z.d, z.c);
  return f;
}

TEST(LineFactorsTest, GraphHoldsLinesOnTheirOwnTangentAndRefusesWhatCannotPlaceThem) {
  SlamGraph g;
  const uint64_t s0 = VariableKey(VariableKind::kSubmap, 'a', 0),
                 s1 = VariableKey(VariableKind::kSubmap, 'a', 1);
  const uint64_t b0 = VariableKey(VariableKind::kSubmap, 'b', 0),
                 b1 = VariableKey(VariableKind::kSubmap, 'b', 1);
  const uint64_t l = VariableKey(VariableKind::kLine, 'a', 0);
  const Eigen::Vector3d p_w(4.0, 1.0, 0.5), d_w = Eigen::Vector3d(0.0, 1.0, 0.3).normalized();
  const Pose3 T1 = LineTestPose(1.0, 0.5, 0.0, 0.3);
  EXPECT_FALSE(g.AddFactor(LineObservationFactor(s0, l, Pose3(), p_w, d_w, 0.01)).ok()) << "unknown submap";
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = s0;
  ASSERT_TRUE(g.AddFactor(prior).ok());
  SlamFactor bad = LineObservationFactor(s0, l, Pose3(), p_w, d_w, 0.01);
  bad.line_direction *= 2.0;
  EXPECT_FALSE(g.AddFactor(bad).ok()) << "direction not of unit length";
  bad = LineObservationFactor(s0, l, Pose3(), p_w, d_w, 0.01);
  bad.line_information(3, 3) = -1.0;
  EXPECT_FALSE(g.AddFactor(bad).ok()) << "information not positive definite";
  bad = LineObservationFactor(s0, VariableKey(VariableKind::kPlane, 'a', 0), Pose3(), p_w, d_w, 0.01);
  EXPECT_FALSE(g.AddFactor(bad).ok()) << "not a line variable";
  ASSERT_TRUE(g.AddFactor(LineObservationFactor(s0, l, Pose3(), p_w, d_w, 0.01)).ok());
  SlamFactor sw;
  sw.kind = FactorKind::kFrameSwitch;
  sw.a = s0;
  sw.b = s1;
  sw.z = T1;
  ASSERT_TRUE(g.AddFactor(sw).ok());
  ASSERT_TRUE(g.AddFactor(LineObservationFactor(s1, l, T1, p_w, d_w, 0.01)).ok());
  g.Update();
  EXPECT_LT(g.Chi2(), 1e-9);
  // The landmark's marginal covariance has its four dimensions and nothing in the two unused ones.
  const auto cov = g.Covariances({l});
  ASSERT_TRUE(cov.ok()) << cov.status().ToString();
  const Matrix6d& c = (*cov)[0];
  for (int k = 0; k < 4; ++k) EXPECT_GT(c(k, k), 0.0) << k;
  EXPECT_EQ(c.bottomRows<2>().norm(), 0.0);
  EXPECT_EQ(c.rightCols<2>().norm(), 0.0);
  // A teammate's floating submaps cannot be tied by a line (four degrees of freedom of six).
  sw.a = b0;
  sw.b = b1;
  ASSERT_TRUE(g.AddFactor(sw).ok());
  const auto status = g.AddFactor(LineObservationFactor(b1, l, T1, p_w, d_w, 0.01));
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.ToString().find("unconnected"), std::string::npos) << status.ToString();
}

}  // namespace
}  // namespace cairn
