#pragma once
// Screens the submap matches between two robots before they enter the SLAM graph. The graph's
// Cauchy loss cannot undo a wrong first tie: the match that first ties a teammate places it, and
// a right match arriving next finds the pair settled in the wrong minimum, which it only bends.
// So the matches of a pair of robots are tested against each other first. Two matches agree when
// the cycle they close through the two robots' chains of frame switches is the identity within
// its covariance (the pairwise test of pairwise_consistency.h, for one pair of robots, with the
// covariances composed to first order along the chains).
//
// Per pair of robots:
// - Until one of its matches is accepted, they are held. The largest set of mutually agreeing
//   held matches is accepted once it has two. A lone match, or matches that all disagree, wait
//   `hold_seconds` from the oldest's arrival for a second opinion; then the best determined one
//   (least covariance determinant) is accepted and the rest are tested against it.
// - Later matches of the pair are tested against every accepted one: a match that disagrees with
//   any is rejected, naming it. A cycle that cannot be composed yet (a teammate's frame switch
//   still on its way, two runs of one robot) counts as agreeing: there is no evidence against it.
// - Each test of a match passes with probability confidence^(1/k) under the stated covariances,
//   k its tests, so that a true match passes all of them with `confidence`.
// - At the end of a run (Decide(.., true)) nothing stays held.
// Every robot of a team screens the same matches (teammates publish theirs). The decisions depend
// on the order of arrival where a hold ends before a contradicting match arrives, and where two
// sets of agreeing matches disagree with each other (the first set to form wins).

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "common/options_visitor.h"
#include "common/timestamp.h"
#include "estimation/graph/pose_graph.h"
#include "estimation/graph/slam_graph_types.h"

namespace cairn {

struct TeamMatchScreenOptions {
  // How long the first matches of a pair of robots wait for one that agrees; 0 accepts a lone
  // first match at once (and disagreeing ones by their covariance).
  double hold_seconds = 30.0;
  double confidence = 0.99;  // that a true match passes all its tests

  void Visit(OptionsVisitor& v) {
    v.Number("hold_seconds", hold_seconds, 0.0, 1e6, "s");
    v.Number("confidence", confidence, 0.5, 0.999999, "probability");
  }
};

struct ScreenedMatch {
  SlamFactor factor;  // as offered
  bool accepted = false;
  std::string reason;  // why it was rejected
};

class TeamMatchScreen {
 public:
  explicit TeamMatchScreen(const TeamMatchScreenOptions& options = {});

  // A frame switch (s_i -> s_i+1) of any robot: the chains the cycles run along.
  void AddFrameSwitch(const SlamFactor& w);
  // A match between origins of two robots; held until Decide() accepts or rejects it. `now` is
  // the robot's data time (Timestamp() before it has any: the match is stamped at the next
  // Decide() with a time).
  void Offer(const SlamFactor& match, Timestamp now);
  // The matches decided since the last call, in the order decided. `final`: the end of the run.
  std::vector<ScreenedMatch> Decide(Timestamp now, bool final);

  size_t held() const;
  // Squared Mahalanobis length of the cycle of two matches between the same two robots (either
  // orientation); nullopt when a chain between their origins is not known.
  std::optional<double> CycleChi2(const SlamFactor& first, const SlamFactor& second) const;

 private:
  struct Relative {
    Pose3 T;
    Matrix6d covariance = Matrix6d::Zero();  // right perturbation (t + R dt, R Exp(dr))
  };
  struct Held {
    SlamFactor factor;
    Timestamp received;
    bool stamped = false;
  };
  struct Pair {
    std::vector<SlamFactor> accepted;
    std::vector<Held> held;
  };
  // Composition and inverse of relative poses with their covariances, to first order.
  static Relative Compose(const Relative& a, const Relative& b);
  static Relative Invert(const Relative& a);
  // The relative pose of origin `to` in origin `from` along one robot's frame switches.
  std::optional<Relative> Segment(uint64_t from, uint64_t to) const;
  void DecideHeld(Pair& pair, Timestamp now, bool final, std::vector<ScreenedMatch>& out) const;
  // Accepts or rejects every held match by its tests against the accepted ones.
  void TestAgainstAccepted(Pair& pair, std::vector<ScreenedMatch>& out) const;

  TeamMatchScreenOptions options_;
  std::map<uint64_t, std::pair<uint64_t, Relative>> switches_;  // from -> (to, relative pose)
  std::map<std::pair<char, char>, Pair> pairs_;
};

}  // namespace cairn
