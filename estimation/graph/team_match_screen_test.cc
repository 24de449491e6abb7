#include "estimation/graph/team_match_screen.h"

#include <cmath>
#include <random>

#include <gtest/gtest.h>

#include "estimation/graph/pairwise_consistency.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

Pose3 PoseXyzYaw(double x, double y, double z, double yaw) {
  return Pose3{Eigen::Vector3d(x, y, z),
               Eigen::Quaterniond(Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()))};
}

// T Exp(d) in the factors' convention (t + R dt, R Exp(dr)).
Pose3 Perturbed(const Pose3& T, const Vector6d& d) {
  return Pose3{T.t + T.R() * d.head<3>(), (T.q * so3::ExpQuaternion(d.tail<3>())).normalized()};
}

Matrix6d Diagonal(double sigma_t, double sigma_yaw, double sigma_tilt) {
  Vector6d s;
  s << sigma_t, sigma_t, sigma_t, sigma_tilt, sigma_tilt, sigma_yaw;
  return s.cwiseAbs2().asDiagonal();
}

uint64_t Origin(char robot, uint64_t index) { return VariableKey(VariableKind::kSubmap, robot, index); }

// Two robots driving their own curves; origins every few metres; the truth of every origin.
struct Team {
  std::vector<Pose3> a, b;
  Matrix6d switch_covariance = Diagonal(0.01, 0.002, 0.001);
  Matrix6d match_covariance = Diagonal(0.02, 0.003, 0.01);

  Team() {
    for (int i = 0; i < 8; ++i) {
      a.push_back(PoseXyzYaw(3.0 * i, 0.5 * std::sin(i), 0.1 * i, 0.2 * i));
      b.push_back(PoseXyzYaw(10.0 - 2.5 * i, 4.0 + 0.3 * i, 0.0, 2.0 - 0.15 * i));
    }
  }
  SlamFactor Switch(char robot, int i, const Vector6d& noise = Vector6d::Zero()) const {
    const std::vector<Pose3>& p = robot == 'a' ? a : b;
    SlamFactor w;
    w.kind = FactorKind::kFrameSwitch;
    w.a = Origin(robot, static_cast<uint64_t>(i));
    w.b = Origin(robot, static_cast<uint64_t>(i + 1));
    w.z = Perturbed(p[static_cast<size_t>(i)].Inverse() * p[static_cast<size_t>(i + 1)], noise);
    w.information = switch_covariance.inverse();
    return w;
  }
  // Match of b/j in a/i, moved by `error` (translation, yaw) off the truth.
  SlamFactor Match(int i, int j, const Vector6d& noise = Vector6d::Zero(), double scale = 1.0) const {
    SlamFactor m;
    m.kind = FactorKind::kMatch;
    m.a = Origin('a', static_cast<uint64_t>(i));
    m.b = Origin('b', static_cast<uint64_t>(j));
    m.z = Perturbed(a[static_cast<size_t>(i)].Inverse() * b[static_cast<size_t>(j)], noise);
    m.information = (scale * match_covariance).inverse();
    return m;
  }
  void Chains(TeamMatchScreen& screen) const {
    for (int i = 0; i + 1 < static_cast<int>(a.size()); ++i) {
      screen.AddFrameSwitch(Switch('a', i));
      screen.AddFrameSwitch(Switch('b', i));
    }
  }
};

Vector6d WrongBy(double metres, double degrees) {
  Vector6d d = Vector6d::Zero();
  d[0] = metres;
  d[5] = degrees * M_PI / 180.0;
  return d;
}

Timestamp At(double seconds) { return Timestamp() + Duration::Seconds(seconds); }

TEST(TeamMatchScreenTest, CycleOfTrueMatchesIsZeroAndOfAWrongOneLarge) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  const auto right = screen.CycleChi2(team.Match(1, 2), team.Match(5, 6));
  ASSERT_TRUE(right.has_value());
  EXPECT_LT(*right, 1e-12);
  // 0.22 m and 1.4 deg off, against sigmas of 2 cm and 0.17 deg per match and a short cycle.
  const auto wrong = screen.CycleChi2(team.Match(1, 2, WrongBy(0.22, 1.4)), team.Match(1, 3));
  ASSERT_TRUE(wrong.has_value());
  EXPECT_GT(*wrong, 3.0 * ChiSquareQuantile(0.99, 6));
  // Along longer chains their drift hides more of the same error.
  const auto far = screen.CycleChi2(team.Match(1, 2, WrongBy(0.22, 1.4)), team.Match(5, 6));
  ASSERT_TRUE(far.has_value());
  EXPECT_LT(*far, *wrong);
}

TEST(TeamMatchScreenTest, EitherOrientationOfAMatchGivesTheSameCycle) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  const SlamFactor m = team.Match(1, 2, WrongBy(0.05, 0.3));
  SlamFactor reversed = m;
  reversed.a = m.b;
  reversed.b = m.a;
  reversed.z = m.z.Inverse();
  const Matrix6d A = Adjoint(m.z);
  reversed.information = (A * m.information.inverse() * A.transpose()).inverse();
  const auto forward = screen.CycleChi2(m, team.Match(4, 4));
  const auto backward = screen.CycleChi2(reversed, team.Match(4, 4));
  ASSERT_TRUE(forward && backward);
  EXPECT_NEAR(*forward, *backward, 1e-6 * *forward);
}

TEST(TeamMatchScreenTest, CycleWithoutAChainIsUnknown) {
  const Team team;
  TeamMatchScreen screen;
  screen.AddFrameSwitch(team.Switch('a', 0));  // b's chain is missing
  EXPECT_FALSE(screen.CycleChi2(team.Match(0, 1), team.Match(1, 3)).has_value());
  EXPECT_TRUE(screen.CycleChi2(team.Match(0, 3), team.Match(1, 3)).has_value());
}

// The composed covariance is right: cycles of noisy true matches along noisy chains have a mean
// squared Mahalanobis length of 6.
TEST(TeamMatchScreenTest, CycleChi2OfNoisyTrueMatchesHasSixDegreesOfFreedom) {
  const Team team;
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  auto draw = [&](const Matrix6d& covariance) {
    Vector6d n;
    for (int k = 0; k < 6; ++k) n[k] = normal(rng);
    return Vector6d(covariance.llt().matrixL() * n);
  };
  double sum = 0.0;
  const int trials = 2000;
  for (int t = 0; t < trials; ++t) {
    TeamMatchScreen screen;
    for (int i = 0; i + 1 < static_cast<int>(team.a.size()); ++i) {
      screen.AddFrameSwitch(team.Switch('a', i, draw(team.switch_covariance)));
      screen.AddFrameSwitch(team.Switch('b', i, draw(team.switch_covariance)));
    }
    const auto chi2 = screen.CycleChi2(team.Match(1, 6, draw(team.match_covariance)),
                                       team.Match(6, 1, draw(team.match_covariance)));
    ASSERT_TRUE(chi2.has_value());
    sum += *chi2;
  }
  // Standard error of the mean: sqrt(12 / 2000) = 0.08.
  EXPECT_NEAR(sum / trials, 6.0, 0.35);
}

TEST(TeamMatchScreenTest, TwoAgreeingMatchesEnterAtOnceAndALaterWrongOneIsRejected) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  screen.Offer(team.Match(1, 2), At(10));
  EXPECT_TRUE(screen.Decide(At(10), false).empty());
  EXPECT_EQ(screen.held(), 1u);
  screen.Offer(team.Match(3, 3), At(11));
  const std::vector<ScreenedMatch> both = screen.Decide(At(11), false);
  ASSERT_EQ(both.size(), 2u);
  EXPECT_TRUE(both[0].accepted && both[1].accepted);
  screen.Offer(team.Match(5, 6, WrongBy(0.22, 1.4)), At(12));
  screen.Offer(team.Match(6, 6), At(12));
  const std::vector<ScreenedMatch> later = screen.Decide(At(12), false);
  ASSERT_EQ(later.size(), 2u);
  EXPECT_FALSE(later[0].accepted);
  EXPECT_NE(later[0].reason.find("a/5 - b/6 disagrees with the accepted match a/1 - b/2"), std::string::npos)
      << later[0].reason;
  EXPECT_TRUE(later[1].accepted);
  EXPECT_EQ(screen.held(), 0u);
}

TEST(TeamMatchScreenTest, ALoneMatchWaitsForTheHold) {
  const Team team;
  TeamMatchScreenOptions options;
  options.hold_seconds = 30.0;
  TeamMatchScreen screen(options);
  team.Chains(screen);
  screen.Offer(team.Match(1, 2), At(100));
  EXPECT_TRUE(screen.Decide(At(129), false).empty());
  const std::vector<ScreenedMatch> out = screen.Decide(At(130), false);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].accepted);
}

TEST(TeamMatchScreenTest, AMatchOfferedBeforeAnyTimeWaitsFromTheFirstTime) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  screen.Offer(team.Match(1, 2), Timestamp());
  EXPECT_TRUE(screen.Decide(At(500), false).empty());
  EXPECT_TRUE(screen.Decide(At(529), false).empty());
  EXPECT_EQ(screen.Decide(At(530), false).size(), 1u);
}

TEST(TeamMatchScreenTest, DisagreeingFirstMatchesAreSettledByTheirCovarianceAfterTheHold) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  // The wrong one first, and less certain (a small overlap's ICP), as in a simulated mission.
  screen.Offer(team.Match(0, 0, WrongBy(0.22, 1.4), 1.5), At(50));
  screen.Offer(team.Match(0, 1), At(50));
  EXPECT_TRUE(screen.Decide(At(60), false).empty());
  EXPECT_EQ(screen.held(), 2u);
  const std::vector<ScreenedMatch> out = screen.Decide(At(80), false);
  ASSERT_EQ(out.size(), 2u);
  EXPECT_TRUE(out[0].accepted);
  EXPECT_EQ(out[0].factor.b, Origin('b', 1));
  EXPECT_FALSE(out[1].accepted);
  EXPECT_EQ(out[1].factor.b, Origin('b', 0));
}

TEST(TeamMatchScreenTest, ThreeMatchesOutvoteAnEarlierWrongOne) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  screen.Offer(team.Match(0, 0, WrongBy(0.3, 2.0)), At(1));
  screen.Offer(team.Match(2, 2), At(2));
  EXPECT_TRUE(screen.Decide(At(2), false).empty());
  screen.Offer(team.Match(4, 5), At(3));
  const std::vector<ScreenedMatch> out = screen.Decide(At(3), false);
  ASSERT_EQ(out.size(), 3u);
  int accepted = 0;
  for (const ScreenedMatch& m : out) {
    accepted += m.accepted ? 1 : 0;
    EXPECT_EQ(m.accepted, m.factor.a != Origin('a', 0));
  }
  EXPECT_EQ(accepted, 2);
}

TEST(TeamMatchScreenTest, TheEndOfARunHoldsNothing) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  screen.Offer(team.Match(1, 2), At(10));
  const std::vector<ScreenedMatch> out = screen.Decide(At(11), true);
  ASSERT_EQ(out.size(), 1u);
  EXPECT_TRUE(out[0].accepted);
  EXPECT_EQ(screen.held(), 0u);
}

TEST(TeamMatchScreenTest, PairsOfRobotsAreScreenedApart) {
  const Team team;
  TeamMatchScreen screen;
  team.Chains(screen);
  screen.Offer(team.Match(1, 2), At(1));
  SlamFactor other = team.Match(2, 3);
  other.b = VariableKey(VariableKind::kSubmap, 'c', 0);
  screen.Offer(other, At(1));
  // Two lone first matches of two pairs: neither corroborates the other.
  EXPECT_TRUE(screen.Decide(At(2), false).empty());
  EXPECT_EQ(screen.held(), 2u);
}

}  // namespace
}  // namespace cairn
