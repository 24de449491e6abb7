#include "mapping/matching/submap_pairing.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace cairn {
namespace {

// A suitable submap whose obstacles fill [0, 4] x [0, 4] of its frame, placed at (x, y) with yaw.
PairingSubmap Placed(const std::string& robot, uint64_t id, double x, double y, double yaw = 0.0,
                     double variance = 0.0) {
  PairingSubmap s;
  s.key = {robot, id};
  s.matchable = true;
  s.box_xy = Eigen::AlignedBox2d(Eigen::Vector2d(0, 0), Eigen::Vector2d(4, 4));
  s.placed = true;
  s.T_world_submap = FourDofTransform(x, y, 0.0, yaw);
  s.covariance = Eigen::Matrix4d::Identity() * variance;
  return s;
}

TEST(SubmapPairingTest, OverlapIsWidenedByTwoRelativeSigmas) {
  SubmapPairing pairing;
  pairing.Update(Placed("a", 1, 0.0, 0.0, 0.0, 0.0));
  pairing.Update(Placed("a", 5, 2.0, 3.0, 0.0, 0.25));  // dsigma = 0.5 m
  SubmapPair pair;
  ASSERT_EQ(pairing.Evaluate({"a", 1}, {"a", 5}, &pair), PairSkip::kNone);
  // Eq. 6.1, 6.2: (2 + 2 * 0.5) * (1 + 2 * 0.5).
  EXPECT_NEAR(pair.overlap_area, 3.0 * 2.0, 1e-12);
  EXPECT_NEAR(pair.relative_sigma.x(), 0.5, 1e-12);
  // Eq. 6.4 with alpha = 0.125.
  EXPECT_NEAR(pair.score, 0.125 * 6.0 + 1.5, 1e-12);
  EXPECT_NEAR(pair.prior.T_a_b.x(), 2.0, 1e-12);
  EXPECT_NEAR(pair.prior.T_a_b.y(), 3.0, 1e-12);
  EXPECT_NEAR(pair.prior.covariance(0, 0), 0.25, 1e-12);
}

TEST(SubmapPairingTest, BoxesApartCountOnlyWhenTheUncertaintyBridgesTheGap) {
  SubmapPairing pairing;
  pairing.Update(Placed("a", 1, 0.0, 0.0));
  pairing.Update(Placed("a", 3, 5.0, 0.0, 0.0, 0.36));  // 1 m apart in x, dsigma 0.6 m
  SubmapPair pair;
  // overlap'_x = -1 + 1.2 = 0.2, overlap'_y = 4 + 1.2: 1.04 m^2, below 2 m^2.
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"a", 3}, &pair), PairSkip::kNoOverlap);
  pairing.Update(Placed("a", 3, 5.0, 0.0, 0.0, 4.0));  // dsigma 2 m: (3) * (8) m^2
  ASSERT_EQ(pairing.Evaluate({"a", 1}, {"a", 3}, &pair), PairSkip::kNone);
  EXPECT_NEAR(pair.overlap_area, 24.0, 1e-9);
}

TEST(SubmapPairingTest, TheBoxTurnsWithTheOrigin) {
  SubmapPairing pairing;
  pairing.Update(Placed("a", 1, 0.0, 0.0));
  // Turned by 180 degrees about (4, 4): its box is [0, 4] x [0, 4] again.
  pairing.Update(Placed("b", 1, 4.0, 4.0, std::numbers::pi));
  SubmapPair pair;
  ASSERT_EQ(pairing.Evaluate({"a", 1}, {"b", 1}, &pair), PairSkip::kNone);
  EXPECT_NEAR(pair.overlap_area, 16.0, 1e-9);
  // The prior's covariance is in A's axes.
  pairing.Update(Placed("a", 1, 0.0, 0.0, std::numbers::pi / 2));
  PairingSubmap b = Placed("b", 1, -4.0, 0.0);
  b.covariance.diagonal() << 1.0, 0.0, 0.0, 0.0;  // x of the world only
  pairing.Update(b);
  ASSERT_EQ(pairing.Evaluate({"a", 1}, {"b", 1}, &pair), PairSkip::kNone);
  EXPECT_NEAR(pair.prior.covariance(0, 0), 0.0, 1e-12);
  EXPECT_NEAR(pair.prior.covariance(1, 1), 1.0, 1e-12);  // A's y is the world's x
}

TEST(SubmapPairingTest, SkipsConsecutiveUnsuitableUnplacedAndDisconnected) {
  SubmapPairing pairing;
  pairing.Update(Placed("a", 1, 0.0, 0.0));
  pairing.Update(Placed("a", 2, 0.5, 0.0));
  pairing.Update(Placed("b", 2, 0.5, 0.0));
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"a", 2}), PairSkip::kConsecutive);
  EXPECT_EQ(pairing.Evaluate({"a", 2}, {"a", 1}), PairSkip::kConsecutive);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"b", 2}), PairSkip::kNone);  // another robot's
  PairingSubmap u = Placed("c", 1, 0.0, 0.0);
  u.matchable = false;
  pairing.Update(u);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"c", 1}), PairSkip::kUnsuitable);
  PairingSubmap n = Placed("c", 2, 0.0, 0.0);
  n.placed = false;
  pairing.Update(n);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"c", 2}), PairSkip::kNotPlaced);
  PairingSubmap o = Placed("c", 4, 0.0, 0.0);
  o.component = 1;
  pairing.Update(o);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"c", 4}), PairSkip::kOtherComponent);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"z", 9}), PairSkip::kNotPlaced);

  // The census counts each of the 15 pairs of the 6 submaps once, by the same verdicts.
  pairing.MarkAttempted({"a", 1}, {"b", 2}, MatchStatus::kNoMatch);
  const std::map<PairSkip, size_t> census = pairing.Census();
  size_t total = 0;
  for (const auto& [skip, count] : census) total += count;
  EXPECT_EQ(total, 15u);
  EXPECT_EQ(census.at(PairSkip::kAttempted), 1u);
  EXPECT_EQ(census.at(PairSkip::kConsecutive), 1u);
  EXPECT_EQ(census.at(PairSkip::kUnsuitable), 5u);  // c/1 with each of the others
  EXPECT_EQ(census.at(PairSkip::kNotPlaced), 4u);   // c/2 with the others but c/1
  EXPECT_EQ(census.at(PairSkip::kOtherComponent), 3u);
  EXPECT_EQ(census.at(PairSkip::kNone), 1u);  // a/2 - b/2
}

TEST(SubmapPairingTest, UnconnectedPairsComeLastWithoutAPriorAndOwnershipSplitsTheWork) {
  SubmapPairingOptions options;
  options.match_unconnected = true;
  SubmapPairing pairing(options);
  pairing.Update(Placed("a", 1, 0.0, 0.0, 0.0, 0.04));
  pairing.Update(Placed("a", 3, 1.0, 0.0, 0.0, 0.09));
  PairingSubmap teammate = Placed("b", 1, 100.0, 0.0);
  teammate.component = 1;
  pairing.Update(teammate);
  PairingSubmap unplaced = Placed("b", 2, 0.0, 0.0);
  unplaced.component = 1;
  unplaced.placed = false;
  pairing.Update(unplaced);
  const std::vector<SubmapPair> candidates = pairing.Candidates();
  ASSERT_EQ(candidates.size(), 3u);  // a/1-a/3 predicted; a/1-b/1, a/3-b/1 searched; b/2 not in the graph
  EXPECT_TRUE(candidates[0].has_prior);
  EXPECT_EQ(candidates[0].b.robot, "a");
  for (size_t i = 1; i < 3; ++i) {
    EXPECT_FALSE(candidates[i].has_prior);
    EXPECT_EQ(candidates[i].b.robot, "b");
    EXPECT_LT(candidates[i].score, candidates[0].score);
  }
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"b", 2}), PairSkip::kNotPlaced);
  // Pairs this robot does not own are a teammate's to try.
  pairing.SetOwnership([](const SubmapKey& a, const SubmapKey& b) { return a.robot == b.robot; });
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"b", 1}), PairSkip::kTeammate);
  EXPECT_EQ(pairing.Candidates().size(), 1u);
}

TEST(SubmapPairingTest, PairsKnownBetterThanTheStereoErrorAreSkipped) {
  // Eq. 6.3 for the thesis' LRU camera: f = 1080 px, b = 0.09 m, 0.5 px at 4 m.
  const double precision = SubmapPairing::StereoPrecision(0.5, 4.0, 1080.0, 0.09);
  EXPECT_NEAR(precision, 0.5 * 16.0 / (1080.0 * 0.09) * std::sqrt(2.0), 1e-12);
  SubmapPairingOptions options;
  options.matcher_precision = precision;
  SubmapPairing pairing(options);
  pairing.Update(Placed("a", 1, 0.0, 0.0, 0.0, 0.0));
  pairing.Update(Placed("a", 7, 1.0, 0.0, 0.0, 0.01));  // dsigma 0.1 m < 0.116 m
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"a", 7}), PairSkip::kKnownBetter);
  pairing.Update(Placed("a", 7, 1.0, 0.0, 0.0, 0.04));  // 0.2 m
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"a", 7}), PairSkip::kNone);
}

TEST(SubmapPairingTest, TwoRobotsTiedByFewFactorsAreMatchedAlthoughKnownBetter) {
  SubmapPairingOptions options;
  options.matcher_precision = 0.116;
  SubmapPairing pairing(options);
  PairingSubmap a = Placed("a", 1, 0.0, 0.0, 0.0, 0.0), a2 = Placed("a", 7, 1.0, 0.0, 0.0, 0.01);
  PairingSubmap b = Placed("b", 1, 1.0, 0.0, 0.0, 0.01);  // dsigma 0.1 m, below the precision
  a.robot_ties = a2.robot_ties = 5;
  b.robot_ties = 1;  // one match alone ties robot b to a
  for (const PairingSubmap& s : {a, a2, b}) pairing.Update(s);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"b", 1}), PairSkip::kNone);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"a", 7}), PairSkip::kKnownBetter);  // one robot's: eq. 6.3
  b.robot_ties = 2;
  pairing.Update(b);
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"b", 1}), PairSkip::kKnownBetter);
  b.robot_ties = 0;
  pairing.Update(b);
  options.min_robot_ties = 0;  // eq. 6.3 alone
  SubmapPairing thesis(options);
  for (const PairingSubmap& s : {a, a2, b}) thesis.Update(s);
  EXPECT_EQ(thesis.Evaluate({"a", 1}, {"b", 1}), PairSkip::kKnownBetter);
}

TEST(SubmapPairingTest, HandsOutEachPairOnceBestScoreFirst) {
  SubmapPairing pairing;
  pairing.Update(Placed("a", 1, 0.0, 0.0, 0.0, 0.0));
  pairing.Update(Placed("a", 3, 0.0, 0.0, 0.0, 1.0));  // full overlap, dsigma 1: the best
  pairing.Update(Placed("b", 1, 2.0, 2.0, 0.0, 0.04));
  const std::vector<SubmapPair> all = pairing.Candidates();
  ASSERT_EQ(all.size(), 3u);
  for (size_t i = 1; i < all.size(); ++i) EXPECT_GE(all[i - 1].score, all[i].score);
  EXPECT_EQ(all.front().a, (SubmapKey{"a", 1}));
  EXPECT_EQ(all.front().b, (SubmapKey{"a", 3}));

  std::vector<std::pair<SubmapKey, SubmapKey>> handed;
  while (std::optional<SubmapPair> p = pairing.Next()) handed.emplace_back(p->a, p->b);
  EXPECT_EQ(handed.size(), 3u);
  EXPECT_FALSE(pairing.Next().has_value());
  EXPECT_TRUE(pairing.Attempted({"a", 3}, {"a", 1}));
  EXPECT_FALSE(pairing.Outcome({"a", 1}, {"a", 3}).has_value());  // running
  pairing.MarkAttempted({"a", 3}, {"a", 1}, MatchStatus::kMatched);
  EXPECT_EQ(pairing.Outcome({"a", 1}, {"a", 3}), MatchStatus::kMatched);
  // New estimates do not bring an attempted pair back.
  pairing.Update(Placed("a", 3, 0.0, 0.0, 0.0, 4.0));
  EXPECT_TRUE(pairing.Candidates().empty());
  EXPECT_EQ(pairing.Evaluate({"a", 1}, {"a", 3}), PairSkip::kAttempted);
}

TEST(SubmapPairingTest, ATeammatesAttemptRemovesThePair) {
  SubmapPairing pairing;
  pairing.Update(Placed("a", 1, 0.0, 0.0));
  pairing.Update(Placed("b", 1, 1.0, 1.0));
  pairing.MarkAttempted({"b", 1}, {"a", 1}, MatchStatus::kNoMatch);
  EXPECT_TRUE(pairing.Candidates().empty());
  EXPECT_EQ(pairing.attempts(), 1u);
}

}  // namespace
}  // namespace cairn
