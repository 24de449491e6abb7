#pragma once
// Which submaps to match, most promising first (thesis 6.1.1, eqs. 6.1 to 6.4). For each pair of
// matchable submaps whose origins the graph has placed in one connected component:
//   overlap'_t = overlap_t + 2 dsigma_t, t in {x, y}            (6.1; overlap_t is signed, so boxes
//   overlap'_xy = overlap'_x * overlap'_y                        apart by less than 2 dsigma count)
// of the xy boxes of what is matched (SubmapFeatures::match_box_xy) in the world; a pair is kept
// when overlap'_xy exceeds min_overlap_area, it is not two consecutive submaps of one robot, and
// its relative pose is not already known better than the matcher could measure it (6.3):
//   mean(dsigma_x, dsigma_y, dsigma_z) >= matcher_precision   (eq. 6.3's stereo error)
// and ranked by score = alpha overlap'_xy + sum_t dsigma_t (6.4).
//
// dsigma is the standard deviation of the relative pose of the two origins. The graph provides
// marginal covariances only, so, as the thesis does, dsigma_t = sqrt(|Sigma_a,tt - Sigma_b,tt|)
// (exact along a chain of odometry from the prior, where the later origin's covariance is the
// earlier one's plus the chain's increments), floored at min_relative_sigma.
//
// Every pair is handed out once: attempts are remembered with their outcome (also those a
// teammate reports), so no pair is tried twice and the exchange can tell which robot tried it.

#include <cstdint>
#include <functional>
#include <map>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/matching/submap_matcher.h"

namespace cairn {

struct SubmapPairingOptions {
  double min_overlap_area = 2.0;   // m^2 (eq. 6.2's overlap'_xy)
  double sigma_widening = 2.0;     // the 2 of eq. 6.1
  double alpha = 0.125;            // 1/m^2 ... eq. 6.4's weight of the overlap
  double matcher_precision = 0.0;  // m; eq. 6.3's right-hand side (StereoPrecision); 0: no pair skipped
  double min_relative_sigma = 0.0;  // m; floor of dsigma_t (rad for yaw)
  bool skip_consecutive = true;
  // Two robots' submaps are not skipped as known better (eq. 6.3) while either robot has fewer
  // than this many factors tying it to the others (matches, sightings, lander observations): the
  // graph's confidence then rests on one match, whose error (a few tenths of a degree) would
  // otherwise fix the robot's place in the team for good. 0: eq. 6.3 alone.
  int64_t min_robot_ties = 2;
  // Pairs whose origins the graph has not tied together (a teammate not yet connected) are tried
  // too, after every other candidate, without a prior: the only way two robots that never met
  // find each other's places.
  bool match_unconnected = false;

  void Visit(OptionsVisitor& v) {
    v.Number("min_overlap_area", min_overlap_area, 0.0, 1e6, "m^2");
    v.Number("sigma_widening", sigma_widening, 0.0, 100.0, "");
    v.Number("alpha", alpha, 0.0, 1e6, "1/m");
    v.Number("matcher_precision", matcher_precision, 0.0, 100.0, "m");
    v.Number("min_relative_sigma", min_relative_sigma, 0.0, 100.0, "m");
    v.Flag("skip_consecutive", skip_consecutive);
    v.Integer("min_robot_ties", min_robot_ties, 0, 1000, "factors");
    v.Flag("match_unconnected", match_unconnected);
  }
};

struct SubmapKey {
  std::string robot;
  uint64_t id = 0;
  auto operator<=>(const SubmapKey&) const = default;
};

// What the pairing knows of one submap.
struct PairingSubmap {
  SubmapKey key;
  bool matchable = false;      // SubmapFeatures::matchable: with descriptors or by the search alone
  Eigen::AlignedBox2d box_xy;  // submap frame (SubmapFeatures::match_box_xy)
  // The graph's estimate of the origin: placed, its component, pose and marginal covariance of
  // (x, y, z, yaw) in the world.
  bool placed = false;
  int component = 0;
  FourDofTransform T_world_submap;
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  uint64_t robot_ties = 0;  // factors tying its robot to the others (SubmapPairingOptions)
};

struct SubmapPair {
  SubmapKey a, b;  // a < b
  double overlap_area = 0.0;  // m^2, eq. 6.2
  Eigen::Vector4d relative_sigma = Eigen::Vector4d::Zero();  // dsigma (x, y, z, yaw), world axes
  double score = 0.0;         // eq. 6.4
  RelativePoseEstimate prior;  // T_a_b and its covariance (A's axes) for the matcher's gate
  bool has_prior = true;       // false for origins the graph has not tied together
};

enum class PairSkip {
  kNone, kUnsuitable, kNotPlaced, kOtherComponent, kConsecutive, kNoOverlap, kKnownBetter, kAttempted, kTeammate
};
std::string_view PairSkipName(PairSkip skip);

class SubmapPairing {
 public:
  explicit SubmapPairing(const SubmapPairingOptions& options = {}) : options_(options) {}

  // Eq. 6.3's right-hand side: the distance error of a point in the image centre at `distance`
  // for a stereo camera of focal length `focal_px` and `baseline`, times sqrt(2).
  static double StereoPrecision(double pixel_error, double distance, double focal_px, double baseline);

  // A new submap or a new estimate of one.
  void Update(const PairingSubmap& submap);
  // Only pairs for which `owned` holds are handed out (the rest are a teammate's to try); unset:
  // every pair.
  void SetOwnership(std::function<bool(const SubmapKey& a, const SubmapKey& b)> owned) { owned_ = std::move(owned); }
  size_t size() const { return submaps_.size(); }

  // Eligible pairs not yet attempted, best score first (ties by key, so the order is deterministic).
  std::vector<SubmapPair> Candidates() const;
  // The best candidate, now marked as attempted (outcome pending).
  std::optional<SubmapPair> Next();

  // Why a pair is not a candidate now (kNone: it is); for diagnostics and tests.
  PairSkip Evaluate(const SubmapKey& a, const SubmapKey& b, SubmapPair* pair = nullptr) const;
  // Every pair of known submaps counted by what Evaluate says of it now.
  std::map<PairSkip, size_t> Census() const;

  // Remembers that a pair was tried (here or by a teammate) and how it ended.
  void MarkAttempted(const SubmapKey& a, const SubmapKey& b, MatchStatus outcome);
  bool Attempted(const SubmapKey& a, const SubmapKey& b) const;
  std::optional<MatchStatus> Outcome(const SubmapKey& a, const SubmapKey& b) const;
  size_t attempts() const { return attempts_.size(); }

 private:
  using PairKey = std::pair<SubmapKey, SubmapKey>;
  static PairKey Ordered(const SubmapKey& a, const SubmapKey& b);
  PairSkip EvaluateOrdered(const PairingSubmap& a, const PairingSubmap& b, SubmapPair* pair) const;

  SubmapPairingOptions options_;
  std::map<SubmapKey, PairingSubmap> submaps_;
  // Outcome of each attempted pair; nullopt while the attempt runs.
  std::map<PairKey, std::optional<MatchStatus>> attempts_;
  std::function<bool(const SubmapKey&, const SubmapKey&)> owned_;
};

}  // namespace cairn
