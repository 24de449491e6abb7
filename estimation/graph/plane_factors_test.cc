#include "estimation/graph/plane_factors.h"

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

Pose3 PlanePose(double x, double y, double z, double yaw) {
  return {Eigen::Vector3d(x, y, z), so3::ExpQuaternion(Eigen::Vector3d(0.0, 0.0, yaw))};
}

// A world plane seen from the submap at T_w_s: (n, d) in the submap's frame.
Eigen::Vector4d PlaneIn(const Pose3& T_w_s, const Eigen::Vector3d& n_w, const Eigen::Vector3d& p_w) {
  const Eigen::Vector3d n = T_w_s.R().transpose() * n_w;
  const Eigen::Vector3d p = T_w_s.R().transpose() * (p_w - T_w_s.t);
  return Eigen::Vector4d(n.x(), n.y(), n.z(), -n.dot(p));
}

TEST(PlaneFactorsTest, ManifoldMinusUndoesPlus) {
  const auto manifold = MakePlaneLandmarkManifold();
  ASSERT_EQ(manifold->AmbientSize(), 7);
  ASSERT_EQ(manifold->TangentSize(), 3);
  const Pose3 x = PlaneLandmarkFrame(Eigen::Vector3d(0.6, 0.8, 0.0), Eigen::Vector3d(1.0, 2.0, 0.5));
  double xb[7], yb[7], back[3];
  PoseToBlock(x, xb);
  const double delta[3] = {0.05, -0.02, 0.3};
  ASSERT_TRUE(manifold->Plus(xb, delta, yb));
  ASSERT_TRUE(manifold->Minus(yb, xb, back));
  for (int i = 0; i < 3; ++i) EXPECT_NEAR(back[i], delta[i], 1e-12);
  // The step moves the plane along its own normal and keeps the quaternion unit.
  const Pose3 y = BlockToPose(yb);
  EXPECT_NEAR((y.t - x.t).dot(x.R().col(2)), 0.3, 1e-12);
  EXPECT_NEAR(Eigen::Vector4d(yb[3], yb[4], yb[5], yb[6]).norm(), 1.0, 1e-12);
}

TEST(PlaneFactorsTest, ResidualVanishesAtTheTruthAndMeasuresTiltAndOffset) {
  const Pose3 T_w_s = PlanePose(2.0, -1.0, 0.2, 0.4);
  const Eigen::Vector3d n_w(0.0, 1.0, 0.0), p_w(3.0, 4.0, 1.0);
  const Eigen::Vector4d z = PlaneIn(T_w_s, n_w, p_w);
  const PlaneObservationResidual r(z, Eigen::Matrix3d::Identity());
  // Any point of the plane and any rotation about its normal is the same landmark.
  const Pose3 l = PlaneLandmarkFrame(n_w, p_w + Eigen::Vector3d(5.0, 0.0, -2.0));
  EXPECT_LT(r.Error(T_w_s, l).norm(), 1e-12);
  const Pose3 spun{l.t, l.q * Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Eigen::Vector3d::UnitZ()))};
  EXPECT_LT(r.Error(T_w_s, spun).norm(), 1e-12);
  // Moving the plane 0.1 m along its normal (away from the submap's side) lowers its offset.
  const Pose3 moved{l.t + 0.1 * n_w, l.q};
  EXPECT_NEAR(r.Error(T_w_s, moved).z(), -0.1, 1e-12);
  EXPECT_NEAR(r.Error(T_w_s, moved).head<2>().norm(), 0.0, 1e-12);
  // Tilting it by 0.02 rad shows in the two normal components only, by 0.02 rad.
  const Pose3 tilted{l.t, Eigen::Quaterniond(Eigen::AngleAxisd(0.02, Eigen::Vector3d::UnitX())) * l.q};
  const Eigen::Vector3d e =
      PlaneObservationResidual(PlaneIn(T_w_s, n_w, l.t), Eigen::Matrix3d::Identity()).Error(T_w_s, tilted);
  EXPECT_NEAR(e.head<2>().norm(), std::sin(0.02), 1e-9);
}

// Two submaps: the second placed by a drifted frame switch, both seeing three walls and a tilted
// panel. The planes pull the second back onto the truth and shrink its covariance.
struct TwoSubmaps {
  Pose3 truth = PlanePose(5.0, 1.0, 0.1, 0.3);
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> planes = {
      {Eigen::Vector3d(1.0, 0.0, 0.0), Eigen::Vector3d(9.0, 0.0, 1.0)},
      {Eigen::Vector3d(0.0, -1.0, 0.0), Eigen::Vector3d(4.0, 6.0, 1.0)},
      {Eigen::Vector3d(-0.6, -0.8, 0.0), Eigen::Vector3d(-3.0, 5.0, 1.0)},
      {Eigen::Vector3d(0.5, 0.0, 0.866).normalized(), Eigen::Vector3d(3.0, -2.0, 0.3)}};
  double plane_sigma = 0.01;  // rad, rad, m
  Matrix6d switch_covariance = Vector6d(0.3, 0.3, 0.05, 0.01, 0.01, 0.05).cwiseAbs2().asDiagonal();
};

SlamFactor Observation(uint64_t submap, uint64_t landmark, const Eigen::Vector4d& z,
                       const Eigen::Vector3d& centroid, double sigma) {
  SlamFactor f;
  f.kind = FactorKind::kPlaneObservation;
  f.a = submap;
  f.b = landmark;
  f.plane = z;
  f.plane_information = Eigen::Matrix3d::Identity() / (sigma * sigma);
  f.z = PlaneLandmarkFrame(z.head<3>(), centroid);
  return f;
}

// Builds the graph with `switch_measured` as the frame switch; planes measured with `noise`.
template <class Rng>
void Build(SlamGraph& g, const TwoSubmaps& w, const Pose3& switch_measured, bool with_planes, Rng* rng) {
  const uint64_t s0 = VariableKey(VariableKind::kSubmap, 'a', 0),
                 s1 = VariableKey(VariableKind::kSubmap, 'a', 1);
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = s0;
  prior.information = Matrix6d::Identity() * 1e8;
  ASSERT_TRUE(g.AddFactor(prior).ok());
  SlamFactor sw;
  sw.kind = FactorKind::kFrameSwitch;
  sw.a = s0;
  sw.b = s1;
  sw.z = switch_measured;
  sw.information = w.switch_covariance.inverse();
  ASSERT_TRUE(g.AddFactor(sw).ok());
  if (!with_planes) return;
  std::normal_distribution<double> n(0.0, 1.0);
  for (size_t i = 0; i < w.planes.size(); ++i) {
    const uint64_t l = VariableKey(VariableKind::kPlane, 'a', i);
    const Pose3 poses[2] = {Pose3(), w.truth};
    const uint64_t keys[2] = {s0, s1};
    for (int k = 0; k < 2; ++k) {
      Eigen::Vector4d z = PlaneIn(poses[k], w.planes[i].first, w.planes[i].second);
      if (rng != nullptr) {
        Eigen::Vector3d u, v;
        TangentAxes(Eigen::Vector3d(z.head<3>()), &u, &v);
        const Eigen::Vector3d e = w.plane_sigma * DrawVector3(n, *rng);
        z.head<3>() = (z.head<3>() + e.x() * u + e.y() * v).normalized();
        z.w() += e.z();
      }
      const Eigen::Vector3d centroid = poses[k].R().transpose() * (w.planes[i].second - poses[k].t);
      ASSERT_TRUE(g.AddFactor(Observation(keys[k], l, z, centroid, w.plane_sigma)).ok());
    }
  }
}

TEST(PlaneFactorsTest, SharedPlanesCorrectADriftedSubmap) {
  const TwoSubmaps w;
  const Pose3 drifted = w.truth * PlanePose(0.4, -0.3, 0.0, 0.04);
  const uint64_t s1 = VariableKey(VariableKind::kSubmap, 'a', 1);
  SlamGraphOptions o;
  for (bool planes : {false, true}) {
    SlamGraph g(o);
    Build<std::mt19937>(g, w, drifted, planes, nullptr);
    g.SolveFull();
    const Pose3 est = *g.Pose(s1);
    const double err = (est.t - w.truth.t).norm(), yaw = est.q.angularDistance(w.truth.q);
    const auto cov = g.Covariances({s1});
    ASSERT_TRUE(cov.ok()) << cov.status().ToString();
    if (!planes) {
      EXPECT_GT(err, 0.4);
      EXPECT_NEAR((*cov)[0](0, 0), 0.09, 1e-3);
    } else {
      // The drifted switch still pulls (0.5 m at 0.3 m sigma against planes at 0.01).
      EXPECT_LT(err, 0.005);
      EXPECT_LT(yaw, 0.001);
      EXPECT_LT((*cov)[0](0, 0), 0.01 * 0.09);
      // The same optimum from the chordal start every robot shares (landmarks re-placed).
      const double cost = g.Chi2();
      g.SolveFinal();
      EXPECT_LT((g.Pose(s1)->t - est.t).norm(), 1e-6);
      EXPECT_NEAR(g.Chi2(), cost, 1e-6);
    }
  }
}

// Monte Carlo consistency: both the switch and the planes drawn from their stated noise; the
// second submap's error against the graph's own marginal covariance (NEES of 6 dimensions).
TEST(PlaneFactorsTest, SubmapCovarianceWithPlanesIsConsistent) {
  const TwoSubmaps w;
  const uint64_t s1 = VariableKey(VariableKind::kSubmap, 'a', 1);
  std::mt19937 rng(7);
  std::normal_distribution<double> n(0.0, 1.0);
  SlamGraphOptions o;
  o.cauchy_c = 0.0;  // the model's consistency, not the robust loss's
  const int runs = 100;
  double nees = 0.0;
  const Eigen::LLT<Matrix6d> chol(w.switch_covariance);
  for (int run = 0; run < runs; ++run) {
    Vector6d e;
    for (int i = 0; i < 6; ++i) e[i] = n(rng);
    e = chol.matrixL() * e;
    // The switch's error: translation in s1's axes (as the residual), rotation on the right.
    const Pose3 measured = w.truth * Pose3{e.head<3>(), so3::ExpQuaternion(e.tail<3>())};
    SlamGraph g(o);
    Build(g, w, measured, true, &rng);
    g.SolveFull();
    const auto cov = g.Covariances({s1});
    ASSERT_TRUE(cov.ok());
    const Pose3 est = *g.Pose(s1);
    Vector6d err;
    err.head<3>() = est.t - w.truth.t;
    err.tail<3>() = so3::Log(est.q * w.truth.q.conjugate());  // left perturbation, as Covariances()
    nees += err.dot((*cov)[0].inverse() * err) / runs;
  }
  std::printf("[ planes] mean NEES of the second origin over %d runs: %.2f (6 degrees of freedom)\n", runs,
              nees);
  // 95 % band of the mean of 100 chi2(6) draws: 6 -+ 1.96 sqrt(12 / 100).
  EXPECT_GT(nees, 5.32);
  EXPECT_LT(nees, 6.68);
}

TEST(PlaneFactorsTest, GraphRefusesObservationsThatCannotPlaceAPlane) {
  SlamGraph g;
  const uint64_t s0 = VariableKey(VariableKind::kSubmap, 'a', 0);
  const uint64_t b0 = VariableKey(VariableKind::kSubmap, 'b', 0),
                 b1 = VariableKey(VariableKind::kSubmap, 'b', 1);
  const uint64_t l = VariableKey(VariableKind::kPlane, 'a', 0);
  const Eigen::Vector4d z(1.0, 0.0, 0.0, -2.0);
  EXPECT_FALSE(g.AddFactor(Observation(s0, l, z, Eigen::Vector3d(2, 0, 0), 0.01)).ok()) << "unknown submap";
  SlamFactor prior;
  prior.kind = FactorKind::kPrior;
  prior.a = s0;
  ASSERT_TRUE(g.AddFactor(prior).ok());
  SlamFactor bad = Observation(s0, l, z, Eigen::Vector3d(2, 0, 0), 0.01);
  bad.plane.head<3>() *= 2.0;
  EXPECT_FALSE(g.AddFactor(bad).ok()) << "normal not of unit length";
  bad = Observation(s0, l, z, Eigen::Vector3d(2, 0, 0), 0.01);
  bad.plane_information(2, 2) = -1.0;
  EXPECT_FALSE(g.AddFactor(bad).ok()) << "information not positive definite";
  SlamFactor to_pose =
      Observation(s0, VariableKey(VariableKind::kLandmark, 'a', 0), z, Eigen::Vector3d(2, 0, 0), 0.01);
  EXPECT_FALSE(g.AddFactor(to_pose).ok()) << "not a plane variable";
  ASSERT_TRUE(g.AddFactor(Observation(s0, l, z, Eigen::Vector3d(2, 0, 0), 0.01)).ok());
  // A teammate's floating submaps cannot be tied by a plane (three degrees of freedom of six).
  SlamFactor sw;
  sw.kind = FactorKind::kFrameSwitch;
  sw.a = b0;
  sw.b = b1;
  ASSERT_TRUE(g.AddFactor(sw).ok());
  const auto status = g.AddFactor(Observation(b1, l, z, Eigen::Vector3d(2, 0, 0), 0.01));
  EXPECT_FALSE(status.ok());
  EXPECT_NE(status.ToString().find("unconnected"), std::string::npos) << status.ToString();
}

}  // namespace
}  // namespace cairn
