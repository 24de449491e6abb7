#pragma once
// Pairwise matching of two gravity-aligned submaps (thesis 6.1.2): descriptor correspondences,
// Hough voting both ways, a 4-DoF RANSAC per vote cluster, the gate against the graph's relative
// estimate, the spread check of each hypothesis' keypoints, the photometric check of each
// hypothesis (photometric_agreement.h), then point-to-plane 4-DoF ICP on the full clouds from the
// best surviving hypothesis, gated and checked photometrically again. Where either submap is
// unsuitable for the descriptors but kept for the grey-level search (SubmapFeatures::searchable),
// only that search proposes hypotheses.
//
// The result is T_a_b (B's origin in A's frame) with its covariance from the ICP (x, y, z, yaw,
// see four_dof_icp.h).
//
// The 6-DoF variant (thesis 6.1 compares it) runs when both submaps' features were described
// with full 3-D frames (SubmapFeatureExtractor with ShotFrame::kFull): Hough votes in x, y, z,
// three-point RANSAC (six_dof_ransac.h) and a 6-DoF ICP (six_dof_icp.h), with the same gate,
// spread and photometric checks and options. Gravity is then used nowhere; the result also holds
// the full transform and its tilt, and T_a_b and the covariance are its x, y, z and yaw. Every rejection says
// which check failed and by how much, because matches that fail are remembered by the pairing and shared with
// teammates.

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "common/status.h"
#include "mapping/matching/correspondence_finder.h"
#include "mapping/matching/four_dof_icp.h"
#include "mapping/matching/four_dof_ransac.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/matching/grey_level_search.h"
#include "mapping/matching/hough_voting.h"
#include "mapping/matching/line_hypotheses.h"
#include "mapping/matching/photometric_agreement.h"
#include "mapping/matching/plane_hypotheses.h"
#include "mapping/matching/submap_feature_extractor.h"

namespace cairn {

struct SubmapMatcherOptions {
  CorrespondenceFinderOptions correspondences;
  HoughVotingOptions hough;
  FourDofRansacOptions ransac;
  IcpOptions icp;
  // Hypotheses from the grey levels seen from above where the descriptors' fail (4-DoF only).
  GreyLevelSearchOptions grey_search;
  // Hypotheses from the submaps' planar faces where the descriptors' fail, before the search
  // (4-DoF only).
  PlaneHypothesisOptions planes;
  // Then from their straight edges (4-DoF only).
  LineHypothesisOptions lines;
  // Hypotheses and the refined match must lie within gate_sigmas standard deviations of the
  // relative estimate in each of x, y, z and yaw (thesis: 2, on x, y, z). The floors stand for the
  // matcher's own error, so a relative estimate known better than the matcher cannot veto it.
  double gate_sigmas = 2.0;
  double gate_floor_translation = 0.05;  // m
  double gate_floor_yaw = 0.01;          // rad
  // Spread check of a hypothesis' inlier keypoints, in each submap: at least this many farther
  // than off_line_distance (xy) from the line through them that leaves the fewest off it (thesis:
  // 2). Applied only where the photometric check below cannot judge (no grey-level texture, too
  // few points compared, the check off): where it can, it refuses what the spread check guards
  // against (alignments that slide along a ridge or turn about a crater's rim) without refusing
  // the true matches whose keypoints all lie on such a rim, as most do on smooth ground.
  int64_t min_off_line_inliers = 2;
  double off_line_distance = 0.5;  // m
  // ICP results refused: too far from the hypothesis it started from (it left the hypothesis'
  // basin), too large a residual, too few pairs.
  double max_refinement_translation = 0.5;  // m
  double max_refinement_yaw = 0.15;         // rad
  double max_icp_rms = 0.05;                // m; point-to-plane
  int64_t min_icp_inliers = 300;
  // Hypotheses refined by the ICP, best first, until one is accepted.
  int64_t max_refined_hypotheses = 2;
  // Photometric check: the correlation of B's grey levels with A's in the same `photometric_voxel`
  // under a hypothesis (before the ICP; the cheap way to drop wrong ones) and under the refined
  // match, where at least `min_photometric_pairs` points are compared. -1 turns a check off.
  double photometric_voxel = 0.05;  // m
  double min_hypothesis_ncc = 0.7;
  double min_match_ncc = 0.9;
  int64_t min_photometric_pairs = 500;
  // After the ICP (4-DoF), x, y and yaw move to where the grey levels correlate best
  // (PhotometricAgreement::Refine), from these steps, with at most this many scores (enough to
  // travel max_refinement_translation and still halve the steps).
  bool grey_refinement = true;
  double grey_refinement_step = 0.04;      // m
  double grey_refinement_step_yaw = 0.01;  // rad
  int64_t grey_refinement_max_scores = 200;
  // Added (as variances) to the ICP's covariance, which treats every residual as independent: the
  // errors the clouds' points share (each a centroid in a 0.05 m voxel, about 0.014 m RMS, and the
  // stereo calibration) do not average out over thousands of pairs.
  double covariance_floor_translation = 0.015;  // m
  double covariance_floor_yaw = 0.002;          // rad

  void Visit(OptionsVisitor& v) {
    v.Section("correspondences", correspondences);
    v.Section("hough", hough);
    v.Section("ransac", ransac);
    v.Section("icp", icp);
    v.Section("grey_search", grey_search);
    v.Section("planes", planes);
    v.Section("lines", lines);
    v.Number("gate_sigmas", gate_sigmas, 0.5, 100.0, "");
    v.Number("gate_floor_translation", gate_floor_translation, 0.0, 100.0, "m");
    v.Number("gate_floor_yaw", gate_floor_yaw, 0.0, 3.2, "rad");
    v.Integer("min_off_line_inliers", min_off_line_inliers, 0, 1'000'000, "keypoints");
    v.Number("off_line_distance", off_line_distance, 0.0, 100.0, "m");
    v.Number("max_refinement_translation", max_refinement_translation, 0.0, 100.0, "m");
    v.Number("max_refinement_yaw", max_refinement_yaw, 0.0, 3.2, "rad");
    v.Number("max_icp_rms", max_icp_rms, 1e-4, 10.0, "m");
    v.Integer("min_icp_inliers", min_icp_inliers, 5, 100'000'000, "pairs");
    v.Integer("max_refined_hypotheses", max_refined_hypotheses, 1, 100, "");
    v.Number("photometric_voxel", photometric_voxel, 0.001, 10.0, "m");
    v.Number("min_hypothesis_ncc", min_hypothesis_ncc, -1.0, 1.0, "correlation");
    v.Number("min_match_ncc", min_match_ncc, -1.0, 1.0, "correlation");
    v.Integer("min_photometric_pairs", min_photometric_pairs, 2, 100'000'000, "points");
    v.Flag("grey_refinement", grey_refinement);
    v.Number("grey_refinement_step", grey_refinement_step, 1e-4, 1.0, "m");
    v.Number("grey_refinement_step_yaw", grey_refinement_step_yaw, 1e-5, 0.5, "rad");
    v.Integer("grey_refinement_max_scores", grey_refinement_max_scores, 7, 100'000, "scores");
    v.Number("covariance_floor_translation", covariance_floor_translation, 0.0, 10.0, "m");
    v.Number("covariance_floor_yaw", covariance_floor_yaw, 0.0, 1.0, "rad");
  }
  Status Validate() const;
};

// What the graph believes of T_a_b before the match, with its covariance (x, y, z, yaw).
struct RelativePoseEstimate {
  FourDofTransform T_a_b;
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Identity();
};

enum class MatchStatus { kMatched, kNoMatch, kUnsuitable };
std::string_view MatchStatusName(MatchStatus status);

struct MatchStageTimes {
  double correspondences_ms = 0.0;
  double hough_ms = 0.0;
  double ransac_ms = 0.0;  // all clusters, with the gate and spread checks
  double icp_ms = 0.0;     // every refinement, the searched candidates' too
  double search_ms = 0.0;  // the grey-level search, when it ran
  double planes_ms = 0.0;  // pairing the planar faces, when it ran
  double lines_ms = 0.0;   // pairing the straight edges, when it ran
  double total_ms = 0.0;
};

struct SubmapMatchResult {
  MatchStatus status = MatchStatus::kNoMatch;
  std::string reason;  // why not matched, or a summary of the match
  FourDofTransform T_a_b;
  // (x, y, z, yaw), A's axes; set when matched: the ICP's (four_dof_icp.h) plus the floors.
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  size_t correspondences = 0;
  size_t clusters = 0;
  size_t hypotheses = 0;       // clusters whose RANSAC reached a consensus
  size_t gated_out = 0;        // hypotheses outside the gate
  size_t spread_rejected = 0;  // hypotheses whose keypoints lie on a line
  size_t photometric_rejected = 0;  // hypotheses and refinements whose grey levels disagree
  size_t refined = 0;          // hypotheses handed to the ICP
  size_t searched = 0;         // candidates of the grey-level search (not in the counts above)
  size_t plane_hypotheses = 0;  // from the planar faces (not in the counts above either)
  size_t line_hypotheses = 0;   // from the straight edges (nor here)
  int dof = 4;                 // 6: the variant without gravity
  Eigen::Isometry3d T_a_b_full = Eigen::Isometry3d::Identity();  // = T_a_b in 4-DoF
  double tilt = 0.0;           // rad; angle between A's z and B's z under T_a_b_full
  size_t ransac_inliers = 0;   // of the hypothesis the match came from
  size_t icp_inliers = 0;
  double icp_rms = 0.0;
  int64_t icp_iterations = 0;
  PhotometricScore photometric;  // of the match, or of the last refinement tried
  MatchStageTimes times;

  bool matched() const { return status == MatchStatus::kMatched; }
};

class SubmapMatcher {
 public:
  explicit SubmapMatcher(const SubmapMatcherOptions& options = {}) : options_(options) {}

  // T_a_b between the submaps of `a` and `b`. Without `prior` there is no gate (a global search,
  // e.g. `cairn match` without a guess).
  SubmapMatchResult Match(const SubmapFeatures& a, const SubmapFeatures& b,
                          const std::optional<RelativePoseEstimate>& prior = std::nullopt) const;

  // Whether `T_a_b` lies within the gate around `prior`, each bound widened by `slack` (m, rad: what
  // a not yet refined candidate may be off by itself); otherwise `why` says which axis is off.
  bool WithinGate(const FourDofTransform& T_a_b, const RelativePoseEstimate& prior, std::string* why,
                  const Eigen::Vector2d& slack = Eigen::Vector2d::Zero()) const;

 private:
  SubmapMatcherOptions options_;
};

}  // namespace cairn
