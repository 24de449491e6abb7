#include "sim/bspline_trajectory.h"

#include <cmath>

#include <gtest/gtest.h>

#include "sim/sim_random.h"

namespace cairn::sim {
namespace {

BSplineTrajectory RandomTrajectory() {
  SimRandom rng(11);
  std::vector<Eigen::Vector3d> p, e;
  for (int i = 0; i < 12; ++i) {
    // Last component first (GCC's argument order), the same data on every compiler.
    const double pz = rng.Uniform(-1, 1), py = rng.Uniform(-2, 2), px = rng.Uniform(-2, 2);
    p.emplace_back(px, py, pz);
    const double ez = rng.Uniform(-0.5, 0.5), ey = rng.Uniform(-0.5, 0.5), ex = rng.Uniform(-3, 3);
    e.emplace_back(ex, ey, ez);
  }
  return BSplineTrajectory(0.5, p, e);
}

TEST(BSplineTrajectoryTest, AnalyticDerivativesMatchFiniteDifferences) {
  const BSplineTrajectory tr = RandomTrajectory();
  EXPECT_DOUBLE_EQ(tr.duration(), 4.5);
  const double h = 1e-5;
  for (double t = 0.1; t < 4.4; t += 0.173) {
    const TrajectoryState s = tr.Evaluate(t), a = tr.Evaluate(t - h), b = tr.Evaluate(t + h);
    const Eigen::Vector3d v_fd = (b.T_world_body.translation() - a.T_world_body.translation()) / (2 * h);
    EXPECT_LT((v_fd - s.velocity).norm(), 1e-6) << t;
    EXPECT_LT(((b.velocity - a.velocity) / (2 * h) - s.acceleration).norm(), 1e-5) << t;
    // Body rate: R^T dR/dt is the skew matrix of omega_body.
    const Eigen::Matrix3d dR = (b.T_world_body.linear() - a.T_world_body.linear()) / (2 * h);
    const Eigen::Matrix3d W = s.T_world_body.linear().transpose() * dR;
    EXPECT_LT((Eigen::Vector3d(W(2, 1), W(0, 2), W(1, 0)) - s.omega_body).norm(), 1e-6) << t;
  }
}

TEST(BSplineTrajectoryTest, IsContinuousAcrossKnotsUpToAcceleration) {
  const BSplineTrajectory tr = RandomTrajectory();
  for (double knot = 0.5; knot < 4.5; knot += 0.5) {
    const TrajectoryState a = tr.Evaluate(knot - 1e-9), b = tr.Evaluate(knot + 1e-9);
    EXPECT_LT((a.acceleration - b.acceleration).norm(), 1e-6) << knot;
    EXPECT_LT((a.omega_body - b.omega_body).norm(), 1e-6) << knot;
  }
}

}  // namespace
}  // namespace cairn::sim
