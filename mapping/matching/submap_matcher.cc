#include "mapping/matching/submap_matcher.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <optional>
#include <vector>

#include "common/elapsed.h"
#include "mapping/matching/grey_level_search.h"
#include "mapping/matching/six_dof_icp.h"
#include "mapping/matching/six_dof_ransac.h"

namespace cairn {
namespace {

using Clock = std::chrono::steady_clock;

std::string Format(const char* format, auto... args) {
  char buffer[256];
  std::snprintf(buffer, sizeof(buffer), format, args...);
  return buffer;
}

struct Hypothesis {
  FourDofTransform T_a_b;   // in 6-DoF, the x, y, z and yaw of T_full
  Eigen::Isometry3d T_full = Eigen::Isometry3d::Identity();
  std::vector<uint32_t> a_keypoints, b_keypoints;  // of the RANSAC inliers
  size_t inliers = 0;
  double rms = 0.0;
  bool grey_agreed = false;  // the photometric check judged it and it passed
};

// Counts rejections by kind and keeps the first message of each, so a failed attempt says how
// every hypothesis ended rather than only how the last one did.
class Rejections {
 public:
  void Add(std::string_view kind, std::string message) {
    for (Entry& e : entries_) {
      if (e.kind == kind) {
        ++e.count;
        return;
      }
    }
    entries_.push_back({std::string(kind), std::move(message), 1});
  }
  std::string Summary(std::string_view none) const {
    if (entries_.empty()) return std::string(none);
    std::string out;
    for (const Entry& e : entries_) {
      if (!out.empty()) out += "; ";
      out += e.count == 1 ? e.first : Format("%zu %s (first: ", e.count, e.kind.c_str()) + e.first + ")";
    }
    return out;
  }

 private:
  struct Entry {
    std::string kind, first;
    size_t count;
  };
  std::vector<Entry> entries_;
};

enum class Verdict { kAgree, kDisagree, kUndecided };

// What a photometric score says against `min_ncc`: undecided with too few points compared or no
// texture on one side (`why` says which), else whether the correlation reaches it.
Verdict JudgeGrey(const PhotometricScore& score, double min_ncc, int64_t min_pairs, std::string* why) {
  if (static_cast<int64_t>(score.pairs) < min_pairs) {
    *why = Format("grey levels compared at %zu points, fewer than %lld", score.pairs, static_cast<long long>(min_pairs));
    return Verdict::kUndecided;
  }
  if (!std::isfinite(score.ncc)) {
    *why = Format("no grey-level texture at the %zu points compared", score.pairs);
    return Verdict::kUndecided;
  }
  if (score.ncc < min_ncc) {
    *why = Format("grey levels correlate %.3f at %zu points, below %.3f", score.ncc, score.pairs, min_ncc);
    return Verdict::kDisagree;
  }
  return Verdict::kAgree;
}

// One ICP refinement in either variant: the transform, its x, y, z, yaw covariance, and how far
// it moved from the hypothesis.
struct Refinement {
  Status status;
  FourDofTransform T_a_b;
  Eigen::Isometry3d T_full = Eigen::Isometry3d::Identity();
  Eigen::Matrix4d covariance = Eigen::Matrix4d::Zero();
  size_t inliers = 0;
  double rms = 0.0;
  int64_t iterations = 0;
  double shift = 0.0;  // m
  double turn = 0.0;   // rad

  // shift and turn: how far T_a_b lies from where the refinement started (4-DoF).
  void MovedFrom(const FourDofTransform& start) {
    const FourDofTransform moved = start.inverse() * T_a_b;
    shift = moved.translation().norm();
    turn = std::abs(moved.yaw());
  }
};

Refinement Refine4(const FourDofIcp& icp, const SubmapFeatures& a, const SubmapFeatures& b, const Hypothesis& h) {
  const FourDofIcpResult fit = icp.Align(a.cloud, b.cloud, h.T_a_b);
  Refinement out{fit.status, fit.T_a_b, fit.T_a_b.ToIsometry(), fit.covariance, fit.inliers, fit.rms, fit.iterations};
  out.MovedFrom(h.T_a_b);
  return out;
}

Refinement Refine6(const SixDofIcp& icp, const SubmapFeatures& a, const SubmapFeatures& b, const Hypothesis& h) {
  const SixDofIcpResult fit = icp.Align(a.cloud, b.cloud, h.T_full);
  Refinement out{fit.status, FourDofTransform::ProjectIsometry(fit.T_a_b), fit.T_a_b, Eigen::Matrix4d::Zero(),
                 fit.inliers, fit.rms, fit.iterations};
  // x, y, z and the rotation about A's z: the 4-DoF parameters, to first order in the tilt.
  static constexpr int kKeep[4] = {0, 1, 2, 5};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 4; ++j) out.covariance(i, j) = fit.covariance(kKeep[i], kKeep[j]);
  const Eigen::Isometry3d moved = h.T_full.inverse() * fit.T_a_b;
  out.shift = moved.translation().norm();
  out.turn = Eigen::AngleAxisd(moved.linear()).angle();
  return out;
}

}  // namespace

std::string_view MatchStatusName(MatchStatus status) {
  switch (status) {
    case MatchStatus::kMatched:
      return "matched";
    case MatchStatus::kNoMatch:
      return "no match";
    case MatchStatus::kUnsuitable:
      return "unsuitable";
  }
  return "?";
}

Status SubmapMatcherOptions::Validate() const {
  if (Status s = ransac.Validate(); !s.ok()) return s;
  if (Status s = icp.Validate(); !s.ok()) return s;
  if (!(gate_sigmas > 0.0)) return InvalidArgumentError("matcher: gate_sigmas must be > 0");
  if (max_refined_hypotheses < 1) return InvalidArgumentError("matcher: max_refined_hypotheses must be >= 1");
  if (!(photometric_voxel > 0.0)) return InvalidArgumentError("matcher: photometric_voxel must be > 0");
  return Status::Ok();
}

bool SubmapMatcher::WithinGate(const FourDofTransform& T_a_b, const RelativePoseEstimate& prior,
                               std::string* why, const Eigen::Vector2d& slack) const {
  static constexpr const char* kAxis[4] = {"x", "y", "z", "yaw"};
  const Eigen::Vector4d d = T_a_b.ToVector() - prior.T_a_b.ToVector();
  for (int i = 0; i < 4; ++i) {
    const double off = i == 3 ? std::abs(WrapAngle(d[i])) : std::abs(d[i]);
    const double sigma = std::sqrt(std::max(prior.covariance(i, i), 0.0));
    const double floor = i == 3 ? options_.gate_floor_yaw : options_.gate_floor_translation;
    const double bound = std::max(options_.gate_sigmas * sigma, floor) + (i == 3 ? slack.y() : slack.x());
    if (!(off <= bound)) {
      if (why != nullptr)
        *why = Format("%s off the relative estimate by %.3f%s, gate %.3f", kAxis[i], off, i == 3 ? " rad" : " m",
                      bound);
      return false;
    }
  }
  return true;
}

SubmapMatchResult SubmapMatcher::Match(const SubmapFeatures& a, const SubmapFeatures& b,
                                       const std::optional<RelativePoseEstimate>& prior) const {
  const Clock::time_point start = Clock::now();
  SubmapMatchResult r;
  auto finish = [&](MatchStatus status, std::string reason) {
    r.status = status;
    r.reason = std::move(reason);
    r.times.total_ms = MillisecondsSince(start);
    return r;
  };
  if (Status s = options_.Validate(); !s.ok()) return finish(MatchStatus::kNoMatch, s.message());
  // A submap the descriptors cannot use may still be matched by the grey-level search alone.
  const bool search_only = !a.suitable() || !b.suitable();
  for (const SubmapFeatures* side : {&a, &b}) {
    if (side->suitable() || (side->searchable && options_.grey_search.enabled)) continue;
    return finish(MatchStatus::kUnsuitable, std::string(side == &a ? "submap A: " : "submap B: ") +
                                                side->suitability.message +
                                                (side->searchable ? "; the grey-level search is off" : ""));
  }
  const bool six = !a.described.gravity_frames;
  r.dof = six ? 6 : 4;
  if (a.described.gravity_frames != b.described.gravity_frames)
    return finish(MatchStatus::kNoMatch, "submaps described for different variants (4-DoF and 6-DoF)");

  // Correspondences and votes.
  Clock::time_point stage = Clock::now();
  const std::vector<KeypointCorrespondence> correspondences =
      search_only ? std::vector<KeypointCorrespondence>()
                  : CorrespondenceFinder(options_.correspondences)
                        .Find(a.described.descriptors, b.described.descriptors);
  r.correspondences = correspondences.size();
  r.times.correspondences_ms = MillisecondsSince(stage);
  stage = Clock::now();
  const HoughResult votes = search_only
                                ? HoughResult()
                                : HoughVoting(options_.hough).Vote(a.described, b.described, correspondences);
  r.clusters = votes.clusters.size();
  r.times.hough_ms = MillisecondsSince(stage);

  // One RANSAC per cluster; gate and spread checks per hypothesis.
  stage = Clock::now();
  const FourDofRansac ransac(options_.ransac);
  const SixDofRansac ransac6(options_.ransac);
  SuitabilityOptions spread_options;
  spread_options.off_line_distance = options_.off_line_distance;
  const SubmapSuitability spread(spread_options);
  std::vector<Hypothesis> hypotheses;
  Rejections rejections;
  std::vector<Eigen::Vector3d> source_b, target_a;
  std::vector<Eigen::Vector3f> inlier_points;
  std::optional<PhotometricAgreement> photometric;  // A's grey levels, built for the first check
  PhotometricScore last_grey;
  const auto Judge = [&](double min_ncc, const auto& T_a_b, std::string* why) {
    if (min_ncc <= -1.0) {
      last_grey = PhotometricScore{};
      *why = "grey levels not checked";
      return Verdict::kUndecided;
    }
    if (!photometric) photometric.emplace(a.cloud, a.cloud_grey, options_.photometric_voxel);
    last_grey = photometric->Score(b.cloud, b.cloud_grey, T_a_b);
    return JudgeGrey(last_grey, min_ncc, options_.min_photometric_pairs, why);
  };
  const auto SpreadOk = [&](const Hypothesis& h, std::string* why) {
    if (options_.min_off_line_inliers <= 0) return true;
    for (const auto* side : {&a, &b}) {
      const std::vector<uint32_t>& ids = side == &a ? h.a_keypoints : h.b_keypoints;
      inlier_points.clear();
      for (const uint32_t id : ids) inlier_points.push_back(side->described.points[id]);
      const int64_t off = spread.OffLineKeypoints(inlier_points);
      if (off < options_.min_off_line_inliers) {
        *why = Format("keypoints on a line: %lld of %zu off it in submap %s, need %lld", static_cast<long long>(off),
                      ids.size(), side == &a ? "A" : "B", static_cast<long long>(options_.min_off_line_inliers));
        return false;
      }
    }
    return true;
  };
  for (const HoughCluster& cluster : votes.clusters) {
    source_b.clear();
    target_a.clear();
    for (const uint32_t m : cluster.members) {
      const KeypointCorrespondence& c = correspondences[m];
      source_b.push_back(b.described.points[c.b].cast<double>());
      target_a.push_back(a.described.points[c.a].cast<double>());
    }
    Hypothesis h;
    std::vector<size_t> inliers;
    Status consensus;
    if (six) {
      Expected<SixDofRansacResult> fit = ransac6.Estimate(source_b, target_a);
      consensus = fit.status();
      if (fit.ok()) {
        h.T_full = fit->T_a_b;
        h.T_a_b = FourDofTransform::ProjectIsometry(h.T_full);
        h.rms = fit->inlier_rms;
        inliers = std::move(fit->inliers);
      }
    } else {
      Expected<FourDofRansacResult> fit = ransac.Estimate(source_b, target_a);
      consensus = fit.status();
      if (fit.ok()) {
        h.T_a_b = fit->T_a_b;
        h.T_full = h.T_a_b.ToIsometry();
        h.rms = fit->inlier_rms;
        inliers = std::move(fit->inliers);
      }
    }
    if (!consensus.ok()) {
      rejections.Add("clusters without consensus",
                     Format("cluster of %zu votes: %s", cluster.members.size(), consensus.message().c_str()));
      continue;
    }
    ++r.hypotheses;
    h.inliers = inliers.size();
    for (const size_t i : inliers) {
      const KeypointCorrespondence& c = correspondences[cluster.members[i]];
      h.a_keypoints.push_back(c.a);
      h.b_keypoints.push_back(c.b);
    }
    std::string why;
    if (prior.has_value() && !WithinGate(h.T_a_b, *prior, &why)) {
      ++r.gated_out;
      rejections.Add("hypotheses outside the gate", "hypothesis " + why);
      continue;
    }
    // The grey levels judge the hypothesis where they can; where they cannot (no texture, little
    // overlap, the check off) the spread of its keypoints must rule out a slide along a line.
    const Verdict grey = six ? Judge(options_.min_hypothesis_ncc, h.T_full, &why)
                             : Judge(options_.min_hypothesis_ncc, h.T_a_b, &why);
    if (grey == Verdict::kDisagree) {
      ++r.photometric_rejected;
      rejections.Add("hypotheses whose grey levels disagree", "hypothesis: " + why);
      continue;
    }
    h.grey_agreed = grey == Verdict::kAgree;
    if (!h.grey_agreed && !SpreadOk(h, &why)) {
      ++r.spread_rejected;
      rejections.Add("hypotheses with keypoints on a line", "hypothesis " + why);
      continue;
    }
    hypotheses.push_back(std::move(h));
  }
  r.times.ransac_ms = MillisecondsSince(stage);
  if (search_only) {
    std::string unsuitable;
    for (const SubmapFeatures* side : {&a, &b}) {
      if (side->suitable()) continue;
      unsuitable += Format("%ssubmap %s (%s)", unsuitable.empty() ? "" : " and ", side == &a ? "A" : "B",
                           side->suitability.message.c_str());
    }
    rejections.Add("no descriptors", unsuitable + " unsuitable for descriptors: grey-level search only");
  } else if (votes.clusters.empty()) {
    rejections.Add("no vote cluster", Format("%zu correspondences, no vote cluster", correspondences.size()));
  }
  std::stable_sort(hypotheses.begin(), hypotheses.end(), [](const Hypothesis& x, const Hypothesis& y) {
    return x.inliers > y.inliers || (x.inliers == y.inliers && x.rms < y.rms);
  });

  // Refinement on the full clouds; true when `h` became the match.
  stage = Clock::now();
  const FourDofIcp icp(options_.icp);
  const SixDofIcp icp6(options_.icp);
  const auto Refined = [&](const Hypothesis& h, std::string_view source, double min_match_ncc) {
    ++r.refined;
    Refinement fit = six ? Refine6(icp6, a, b, h) : Refine4(icp, a, b, h);
    r.icp_inliers = fit.inliers;
    r.icp_rms = fit.rms;
    r.icp_iterations = fit.iterations;
    r.ransac_inliers = h.inliers;
    if (!fit.status.ok()) {
      rejections.Add("refinements failed", fit.status.message());
      return false;
    }
    if (!six && options_.grey_refinement && min_match_ncc > -1.0) {
      if (!photometric) photometric.emplace(a.cloud, a.cloud_grey, options_.photometric_voxel);
      fit.T_a_b = photometric->Refine(b.cloud, b.cloud_grey, fit.T_a_b, options_.grey_refinement_step,
                                      options_.grey_refinement_step_yaw,
                                      static_cast<int>(options_.grey_refinement_max_scores), nullptr);
      // Not the ICP again from there: on the team missions it slid back (seed 3: 10 matches
      // within 5 cm and 0.5 deg instead of 13).
      fit.T_full = fit.T_a_b.ToIsometry();
      fit.MovedFrom(h.T_a_b);
    }
    std::string why;
    if (fit.shift > options_.max_refinement_translation || fit.turn > options_.max_refinement_yaw) {
      rejections.Add("refinements moved too far",
                     Format("icp left the hypothesis by %.3f m and %.3f rad", fit.shift, fit.turn));
    } else if (fit.rms > options_.max_icp_rms) {
      rejections.Add("refinements with a high residual",
                     Format("icp residual %.3f m above %.3f m", fit.rms, options_.max_icp_rms));
    } else if (static_cast<int64_t>(fit.inliers) < options_.min_icp_inliers) {
      rejections.Add("refinements with few pairs", Format("icp paired %zu points, fewer than %lld", fit.inliers,
                                                          static_cast<long long>(options_.min_icp_inliers)));
    } else if (prior.has_value() && !WithinGate(fit.T_a_b, *prior, &why)) {
      rejections.Add("refinements outside the gate", "refined match " + why);
    } else if (const Verdict grey =
                   six ? Judge(min_match_ncc, fit.T_full, &why) : Judge(min_match_ncc, fit.T_a_b, &why);
               grey == Verdict::kDisagree) {
      ++r.photometric_rejected;
      r.photometric = last_grey;
      rejections.Add("refinements whose grey levels disagree", "refined match: " + why);
    } else if (grey == Verdict::kUndecided && h.grey_agreed && !SpreadOk(h, &why)) {
      ++r.spread_rejected;
      rejections.Add("refinements with keypoints on a line", "refined match: " + why);
    } else {
      r.photometric = last_grey;
      r.T_a_b = fit.T_a_b;
      r.T_a_b_full = fit.T_full;
      r.tilt = FourDofTransform::TiltOf(fit.T_full.linear());
      r.covariance = fit.covariance;
      const double ft = options_.covariance_floor_translation, fy = options_.covariance_floor_yaw;
      r.covariance.diagonal() += Eigen::Vector4d(ft * ft, ft * ft, ft * ft, fy * fy);
      r.status = MatchStatus::kMatched;
      r.reason = std::string(source) + Format("; icp %zu pairs, rms %.4f m", fit.inliers, fit.rms) +
                 (grey == Verdict::kAgree ? Format("; grey levels correlate %.3f", r.photometric.ncc)
                                          : "; " + why + ": geometry only");
      return true;
    }
    return false;
  };
  const size_t tries = std::min(hypotheses.size(), static_cast<size_t>(options_.max_refined_hypotheses));
  for (size_t k = 0; k < tries; ++k) {
    const Hypothesis& h = hypotheses[k];
    if (Refined(h, Format("%zu RANSAC inliers of %zu correspondences", h.inliers, correspondences.size()),
                options_.min_match_ncc)) {
      r.times.icp_ms = MillisecondsSince(stage);
      return finish(MatchStatus::kMatched, r.reason);
    }
  }
  r.times.icp_ms = MillisecondsSince(stage);

  // A hypothesis from another source than the descriptors: the gate, then the grey levels, which
  // must agree (undecided is refused too: no keypoints vouch for it), then the refinement.
  const auto Alternative = [&](const FourDofTransform& T_a_b, const char* kind, const std::string& source,
                               double min_match_ncc, const Eigen::Vector2d& gate_slack) {
    Hypothesis h;
    h.T_a_b = T_a_b;
    h.T_full = h.T_a_b.ToIsometry();
    std::string why;
    if (prior.has_value() && !WithinGate(h.T_a_b, *prior, &why, gate_slack)) {
      rejections.Add(Format("%ss outside the gate", kind), Format("%s ", kind) + why);
      return false;
    }
    if (Judge(options_.min_hypothesis_ncc, h.T_a_b, &why) != Verdict::kAgree) {
      rejections.Add(Format("%ss whose grey levels disagree", kind), Format("%s: ", kind) + why);
      return false;
    }
    h.grey_agreed = true;
    const auto icp_start = Clock::now();
    const bool matched = Refined(h, source, min_match_ncc);
    r.times.icp_ms += MillisecondsSince(icp_start);
    return matched;
  };

  // Where the descriptors gave no hypothesis that held, pairings of planar faces (cheap, few).
  // Faces of man-made things repeat (a crate's four sides): the grey levels tell which is which.
  if (!six && options_.planes.enabled && !a.planes.empty() && !b.planes.empty()) {
    stage = Clock::now();
    const std::vector<PlaneHypothesis> paired = PlaneHypotheses(options_.planes).Find(a.planes, b.planes);
    r.times.planes_ms = MillisecondsSince(stage);
    for (const PlaneHypothesis& candidate : paired) {
      ++r.plane_hypotheses;
      if (Alternative(candidate.T_a_b, "plane pairing",
                      Format("planar faces paired (smallest %.1f m^2)", candidate.area),
                      options_.min_match_ncc, Eigen::Vector2d::Zero()))
        return finish(MatchStatus::kMatched, r.reason);
    }
  }

  // Then pairings of straight edges (man-made things too small or noisy for planes).
  if (!six && options_.lines.enabled && !a.lines.empty() && !b.lines.empty()) {
    stage = Clock::now();
    const std::vector<LineHypothesis> paired = LineHypotheses(options_.lines).Find(a.lines, b.lines);
    r.times.lines_ms = MillisecondsSince(stage);
    for (const LineHypothesis& candidate : paired) {
      ++r.line_hypotheses;
      if (Alternative(candidate.T_a_b, "edge pairing",
                      Format("straight edges paired (%d agree, shortest %.1f m)", candidate.edges_agreeing,
                             candidate.length),
                      options_.min_match_ncc, Eigen::Vector2d::Zero()))
        return finish(MatchStatus::kMatched, r.reason);
    }
  }

  // Where neither gave a hypothesis that held, the grey levels seen from above are
  // searched for one (4-DoF only: the search turns about gravity).
  if (!six && options_.grey_search.enabled) {
    stage = Clock::now();
    // With a relative estimate, only the yaws its gate admits.
    Eigen::Vector2d yaw_window(0.0, 4.0);
    if (prior.has_value()) {
      const double sigma = std::sqrt(std::max(prior->covariance(3, 3), 0.0));
      yaw_window = {prior->T_a_b.yaw(), std::max(options_.gate_sigmas * sigma, options_.gate_floor_yaw)};
    }
    const GreyLevelSearch search(options_.grey_search);
    Expected<GreyLevelSearchResult> found =
        search.Search(a.cloud, a.cloud_grey, b.cloud, b.cloud_grey, yaw_window);
    // The gate before the refinement allows for the search's cells and yaw steps; the refined
    // match meets the gate itself.
    const Eigen::Vector2d slack = search.SearchSlack(b.cloud);
    r.times.search_ms = MillisecondsSince(stage);
    if (!found.ok()) {
      rejections.Add("grey-level search refused", found.status().message());
    } else {
      if (found->candidates.empty())
        rejections.Add("grey-level search without a candidate", "grey-level search: no candidate");
      for (const GreyLevelCandidate& candidate : found->candidates) {
        ++r.searched;
        if (Alternative(candidate.T_a_b, "searched candidate",
                        Format("grey-level search, raster correlation %.3f over %lld cells",
                               candidate.correlation, static_cast<long long>(candidate.overlap_cells)),
                        std::max(options_.min_match_ncc, options_.grey_search.min_match_ncc), slack))
          return finish(MatchStatus::kMatched, r.reason);
      }
    }
  }
  return finish(MatchStatus::kNoMatch, rejections.Summary("no hypothesis refined"));
}

}  // namespace cairn
