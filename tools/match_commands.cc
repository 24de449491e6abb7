// cairn match: one 4-DoF submap match between two submap files (mapping/matching/submap_matcher.h),
// printed as JSON.
// cairn bench match: features and matching timed on the submaps of cairnd runs, with recall and
// precision against the simulator's truth in their submaps/index.csv.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <numeric>
#include <optional>
#include <sstream>
#include <string>
#include <unordered_set>
#include <vector>

#include "common/json_writer.h"
#include "estimation/graph/pairwise_consistency.h"
#include "mapping/matching/submap_feature_extractor.h"
#include "mapping/matching/submap_matcher.h"
#include "mapping/submap_codec.h"
#include "tools/commands.h"
#include "tools/sample_median.h"
#include "tools/submap_truth.h"

namespace cairn::tools {
namespace {

constexpr const char* kMatchUsage =
    "usage: cairn match A.submap B.submap [--guess x,y,z,yaw] [--sigma sx,sy,sz,syaw] [--dof 4|6]\n"
    "  Matches submap B against submap A and prints T_a_b (B's origin in A's frame) as JSON.\n"
    "  --guess   what is known of T_a_b (m, m, m, rad); the hypotheses and the result must lie within\n"
    "            2 sigma of it. Without it the search is global.\n"
    "  --sigma   standard deviations of the guess (default 1,1,0.5,0.3)\n"
    "  --dof     4: gravity-aligned submaps (default); 6: the variant that does not use gravity\n";

// Comma-separated finite numbers, exactly `count` of them.
bool ParseList(const std::string& s, size_t count, std::vector<double>* out) {
  return ParseNumberList(s, out) && out->size() == count;
}

// x, y, z, yaw and the full matrix (in 6-DoF with its roll and pitch; `tilt` says how much).
void WriteTransform(JsonWriter& j, const SubmapMatchResult& result) {
  const FourDofTransform& T = result.T_a_b;
  j.Key("T_a_b").BeginObject();
  j.Field("x", T.x()).Field("y", T.y()).Field("z", T.z()).Field("yaw", T.yaw()).Field("tilt", result.tilt);
  j.Key("matrix").BeginArray();
  const Eigen::Matrix4d m = result.T_a_b_full.matrix();
  for (int r = 0; r < 4; ++r) {
    j.BeginArray();
    for (int c = 0; c < 4; ++c) j.Number(m(r, c));
    j.EndArray();
  }
  j.EndArray().EndObject();
}

void WriteFeatures(JsonWriter& j, const char* key, const std::string& path, const SubmapFeatures& f) {
  j.Key(key).BeginObject();
  j.Field("file", path);
  j.Field("suitable", f.suitable());
  j.Field("suitability", f.suitability.message);
  j.Field("searchable", f.searchable);
  j.Field("ground_area_m2", f.ground_area);
  j.Field("points", f.suitability.points);
  j.Field("obstacle_points", f.suitability.obstacle_points);
  j.Field("keypoints", f.keypoints.points.size());
  j.Field("described_keypoints", f.described.size());
  j.Field("keypoints_ms", f.keypoint_ms);
  j.Field("descriptors_ms", f.descriptor_ms);
  j.EndObject();
}

struct IndexedSubmap : SubmapWithTruth {
  SubmapFeatures features;
};

// The rows of DIR/submaps/index.csv that have a true pose, with their submap files.
Status ReadIndexedSubmaps(const std::string& dir, std::vector<IndexedSubmap>* out) {
  std::vector<SubmapWithTruth> read;
  if (Status s = ReadSubmapsWithTruth(dir, &read); !s.ok()) return s;
  for (SubmapWithTruth& r : read) {
    IndexedSubmap s;
    static_cast<SubmapWithTruth&>(s) = std::move(r);
    out->push_back(std::move(s));
  }
  return Status::Ok();
}

// Share of B's points within a 0.1 m voxel (or a neighbouring one) of A's points under T_a_b.
double TrueOverlap(const Submap& a, const Submap& b, const FourDofTransform& T_a_b) {
  constexpr double kVoxel = 0.1;
  auto key = [](const Eigen::Vector3d& p) {
    const int64_t x = static_cast<int64_t>(std::floor(p.x() / kVoxel)) & 0x1fffff;
    const int64_t y = static_cast<int64_t>(std::floor(p.y() / kVoxel)) & 0x1fffff;
    const int64_t z = static_cast<int64_t>(std::floor(p.z() / kVoxel)) & 0x1fffff;
    return x | y << 21 | z << 42;
  };
  std::unordered_set<int64_t> occupied;
  for (const CloudPoint& c : a.points()) {
    if (c.p.allFinite()) occupied.insert(key(c.p.cast<double>()));
  }
  size_t near = 0, total = 0;
  for (const CloudPoint& c : b.points()) {
    if (!c.p.allFinite()) continue;
    ++total;
    const Eigen::Vector3d q = T_a_b * c.p.cast<double>();
    bool hit = false;
    for (int dx = -1; dx <= 1 && !hit; ++dx)
      for (int dy = -1; dy <= 1 && !hit; ++dy)
        for (int dz = -1; dz <= 1 && !hit; ++dz) hit = occupied.count(key(q + kVoxel * Eigen::Vector3d(dx, dy, dz))) != 0;
    near += hit;
  }
  return total == 0 ? 0.0 : static_cast<double>(near) / static_cast<double>(total);
}

// Which pairs the bench tries, by whether their submaps are suitable for the descriptors.
enum class PairSet { kSuitable, kAll, kSearchOnly };

}  // namespace

constexpr const char* kBenchMatchUsage =
    "usage: cairn bench match OUT_DIR... [--min-overlap F (0.3)] [--wire-bits OFFSET,INTENSITY]\n"
    "                         [--no-photometric] [--no-grey-search] [--no-grey-refinement]\n"
    "                         [--no-planes] [--no-lines] [--dof 4|6] [--suitable-only | --search-only]\n"
    "  OUT_DIR: cairnd output folders of simulated runs of one world (submaps/ with index.csv)\n"
    "  --wire-bits: first send every submap through the wire format at these bit counts\n"
    "               (mapping.submap.wire_offset_bits 1..4, wire_intensity_bits 1..8)\n"
    "  --no-photometric: geometry only, the keypoint spread check on every hypothesis (thesis 6.1)\n"
    "  --no-grey-search: hypotheses from the descriptors only (no search of the grey levels from above)\n"
    "  --no-grey-refinement: the ICP's x, y and yaw as they are (not moved to the grey levels' best)\n"
    "  --no-planes: no hypotheses from pairs of the submaps' planar faces\n"
    "  --no-lines: no hypotheses from pairs of the submaps' straight edges\n"
    "  --dof 6: the matcher's variant without gravity; a match must then also be level within 0.5 deg\n"
    "  --suitable-only: only pairs of submaps suitable for the descriptors (thesis 6.1.1)\n"
    "  --search-only: only pairs with a submap kept for the grey-level search alone\n";

int RunBenchMatch(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchMatchUsage);
  std::vector<std::string> dirs;
  double min_overlap = 0.3;
  std::vector<double> wire_bits;  // offset, intensity; empty: the submaps as read
  SubmapMatcherOptions matcher_options;
  ShotFrame frame = ShotFrame::kGravity;
  PairSet pair_set = PairSet::kAll;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    std::vector<double> v;
    if (a == "--min-overlap" && i + 1 < args.args.size() && ParseList(args.args[i + 1], 1, &v)) {
      min_overlap = v[0];
      ++i;
    } else if (a == "--wire-bits" && i + 1 < args.args.size() && ParseList(args.args[i + 1], 2, &v)) {
      wire_bits = v;
      ++i;
    } else if (a == "--no-photometric") {
      matcher_options.min_hypothesis_ncc = matcher_options.min_match_ncc = -1.0;
      matcher_options.grey_search.enabled = false;  // both need the grey levels
      matcher_options.grey_refinement = false;
    } else if (a == "--no-grey-search") {
      matcher_options.grey_search.enabled = false;
    } else if (a == "--no-grey-refinement") {
      matcher_options.grey_refinement = false;
    } else if (a == "--no-planes") {
      matcher_options.planes.enabled = false;
    } else if (a == "--no-lines") {
      matcher_options.lines.enabled = false;
    } else if (a == "--suitable-only") {
      pair_set = PairSet::kSuitable;
    } else if (a == "--search-only") {
      pair_set = PairSet::kSearchOnly;
    } else if (a == "--dof" && i + 1 < args.args.size() &&
               (args.args[i + 1] == std::string("4") || args.args[i + 1] == std::string("6"))) {
      frame = args.args[++i] == std::string("6") ? ShotFrame::kFull : ShotFrame::kGravity;
    } else if (a.empty() || a[0] == '-') {
      std::fputs(kBenchMatchUsage, stderr);
      return 2;
    } else {
      dirs.push_back(a);
    }
  }
  if (dirs.empty()) {
    std::fprintf(stderr, "cairn bench match: name at least one cairnd output folder (e.g. out/rover)\n");
    return 2;
  }
  std::vector<IndexedSubmap> submaps;
  for (const std::string& d : dirs) {
    if (Status s = ReadIndexedSubmaps(d, &submaps); !s.ok()) {
      std::fprintf(stderr, "cairn bench match: %s\n", s.ToString().c_str());
      return 1;
    }
  }
  if (!wire_bits.empty()) {
    for (IndexedSubmap& s : submaps) {
      SubmapMetadata m = s.submap->metadata();
      m.options.wire_offset_bits = static_cast<int64_t>(wire_bits[0]);
      m.options.wire_intensity_bits = static_cast<int64_t>(wire_bits[1]);
      const Submap coarse(m, s.submap->points(), std::make_unique<octomap::OcTree>(s.submap->tree()));
      auto bytes = SubmapCodec::Encode(coarse);
      auto back =
          bytes.ok() ? SubmapCodec::Decode(*bytes) : Expected<std::shared_ptr<const Submap>>(bytes.status());
      if (!back.ok()) {
        std::fprintf(stderr, "cairn bench match: %s/%llu: %s\n", s.robot.c_str(),
                     static_cast<unsigned long long>(s.id), back.status().ToString().c_str());
        return 1;
      }
      s.submap = *back;
    }
  }
  const SubmapFeatureExtractor extractor({}, frame);
  std::vector<double> feature_ms;
  size_t suitable = 0, searchable = 0;
  for (IndexedSubmap& s : submaps) {
    s.features = extractor.Extract(*s.submap);
    feature_ms.push_back(s.features.keypoint_ms + s.features.descriptor_ms);
    suitable += s.features.suitable();
    searchable += s.features.searchable;
  }
  std::printf(
      "cairn bench match: %zu submaps with true origins from %zu folders, %zu suitable, %zu for the "
      "grey-level "
      "search only\n",
      submaps.size(), dirs.size(), suitable, searchable);
  std::printf("  keypoints + descriptors per submap: median %.1f ms, max %.1f ms\n", Median(feature_ms),
              feature_ms.empty() ? NAN : *std::max_element(feature_ms.begin(), feature_ms.end()));
  const SubmapMatcher matcher(matcher_options);
  std::vector<double> match_ms, good_error_m, good_error_deg, nees;
  // Per stage, over the pairs where it ran.
  std::map<std::string, std::vector<double>> stage_ms;
  size_t nees_inside = 0;
  const double chi2_95 = ChiSquareQuantile(0.95, 4);
  size_t positives = 0, found = 0, matched = 0, correct = 0, negatives = 0, false_matches = 0;
  for (size_t i = 0; i < submaps.size(); ++i) {
    for (size_t j = i + 1; j < submaps.size(); ++j) {
      const IndexedSubmap& a = submaps[i];
      const IndexedSubmap& b = submaps[j];
      if (a.robot == b.robot && (a.id + 1 == b.id || b.id + 1 == a.id)) continue;
      if (!a.features.matchable() || !b.features.matchable()) continue;
      if (pair_set == PairSet::kSuitable && (!a.features.suitable() || !b.features.suitable())) continue;
      if (pair_set == PairSet::kSearchOnly && a.features.suitable() && b.features.suitable()) continue;
      const FourDofTransform truth = a.T_world_submap.inverse() * b.T_world_submap;
      const double overlap = std::max(TrueOverlap(*a.submap, *b.submap, truth),
                                      TrueOverlap(*b.submap, *a.submap, truth.inverse()));
      const SubmapMatchResult r = matcher.Match(a.features, b.features);
      match_ms.push_back(r.times.total_ms);
      for (const auto& [stage, ms] :
           {std::pair<const char*, double>{"correspondences", r.times.correspondences_ms},
            {"hough", r.times.hough_ms},
            {"ransac", r.times.ransac_ms},
            {"icp", r.times.icp_ms},
            {"search", r.times.search_ms},
            {"planes", r.times.planes_ms},
            {"lines", r.times.lines_ms}}) {
        if (ms > 0.0) stage_ms[stage].push_back(ms);
      }
      const FourDofTransform error = truth.inverse() * r.T_a_b;
      const bool good = r.matched() && error.translation().norm() <= 0.05 && std::abs(error.yaw()) <= 0.5 * M_PI / 180 &&
                        r.tilt <= 0.5 * M_PI / 180;
      matched += r.matched();
      correct += good;
      if (r.matched()) {
        // The matcher's covariance against its actual error (x, y, z, yaw in A's axes).
        Eigen::Vector4d d = r.T_a_b.ToVector() - truth.ToVector();
        d[3] = WrapAngle(d[3]);
        nees.push_back(d.dot(r.covariance.ldlt().solve(d)));
        nees_inside += nees.back() <= chi2_95 ? 1 : 0;
      }
      if (good) {
        good_error_m.push_back(error.translation().norm());
        good_error_deg.push_back(std::abs(error.yaw()) * 180 / M_PI);
      }
      if (overlap >= min_overlap) {
        ++positives;
        found += good;
      } else if (overlap < 0.01) {
        ++negatives;
        false_matches += r.matched();
      }
      std::printf("  %s/%llu - %s/%llu: overlap %3.0f %%, %-10s", a.robot.c_str(), static_cast<unsigned long long>(a.id),
                  b.robot.c_str(), static_cast<unsigned long long>(b.id), 100.0 * overlap,
                  std::string(MatchStatusName(r.status)).c_str());
      if (r.matched()) {
        std::printf(" error %.3f m %.2f deg, NEES %.1f, grey levels %.3f", error.translation().norm(),
                    std::abs(error.yaw()) * 180 / M_PI, nees.back(), r.photometric.ncc);
        if (r.dof == 6) std::printf(", tilt %.2f deg", r.tilt * 180 / M_PI);
      }
      std::printf(" (%s)", r.reason.c_str());
      std::printf(", %.0f ms\n", r.times.total_ms);
    }
  }
  std::printf("  matching per pair (with ICP): median %.1f ms, max %.1f ms over %zu pairs\n", Median(match_ms),
              match_ms.empty() ? NAN : *std::max_element(match_ms.begin(), match_ms.end()), match_ms.size());
  std::printf("  per stage, median ms over the pairs where it ran (sum of all pairs' ms):");
  for (const auto& [stage, ms] : stage_ms)
    std::printf(" %s %.1f over %zu (%.0f)", stage.c_str(), Median(ms), ms.size(),
                std::accumulate(ms.begin(), ms.end(), 0.0));
  std::printf("\n");
  std::printf("  recall: %zu of %zu pairs with >= %.0f %% true overlap matched within 5 cm and 0.5 deg\n", found,
              positives, 100.0 * min_overlap);
  std::printf("  precision: %zu of %zu matches within 5 cm and 0.5 deg; %zu of %zu pairs without overlap matched\n",
              correct, matched, false_matches, negatives);
  std::printf("  error of those within: median %.4f m %.3f deg, max %.4f m %.3f deg\n", Median(good_error_m),
              Median(good_error_deg),
              good_error_m.empty() ? NAN : *std::max_element(good_error_m.begin(), good_error_m.end()),
              good_error_deg.empty() ? NAN : *std::max_element(good_error_deg.begin(), good_error_deg.end()));
  const double nees_mean =
      nees.empty() ? NAN : std::accumulate(nees.begin(), nees.end(), 0.0) / static_cast<double>(nees.size());
  std::printf(
      "  NEES of every match (4 where the covariance is right): mean %.1f, median %.1f over %zu matches, %zu "
      "inside the 95 %% bound (%.2f)\n",
      nees_mean, Median(nees), nees.size(), nees_inside, chi2_95);
  return 0;
}

int RunMatch(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kMatchUsage);
  std::vector<std::string> files;
  std::optional<RelativePoseEstimate> prior;
  std::vector<double> guess, sigma = {1.0, 1.0, 0.5, 0.3};
  ShotFrame frame = ShotFrame::kGravity;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--guess" && has_value) {
      if (!ParseList(args.args[++i], 4, &guess)) {
        std::fprintf(stderr, "cairn match: --guess needs four finite numbers x,y,z,yaw, got '%s'\n", args.args[i]);
        return 2;
      }
    } else if (a == "--sigma" && has_value) {
      if (!ParseList(args.args[++i], 4, &sigma) || sigma[0] <= 0 || sigma[1] <= 0 || sigma[2] <= 0 ||
          sigma[3] <= 0) {
        std::fprintf(stderr, "cairn match: --sigma needs four positive numbers sx,sy,sz,syaw, got '%s'\n",
                     args.args[i]);
        return 2;
      }
    } else if (a == "--dof" && has_value) {
      const std::string dof = args.args[++i];
      if (dof != "4" && dof != "6") {
        std::fprintf(stderr, "cairn match: --dof %s: 4 or 6\n", dof.c_str());
        return 2;
      }
      frame = dof == "6" ? ShotFrame::kFull : ShotFrame::kGravity;
    } else if (!a.empty() && a[0] == '-') {
      std::fprintf(stderr, "cairn match: unknown or incomplete option '%s'\n%s", a.c_str(), kMatchUsage);
      return 2;
    } else {
      files.push_back(a);
    }
  }
  if (files.size() != 2) {
    std::fputs(kMatchUsage, stderr);
    return 2;
  }
  if (!guess.empty()) {
    prior.emplace();
    prior->T_a_b = FourDofTransform(guess[0], guess[1], guess[2], guess[3]);
    prior->covariance = Eigen::Vector4d(sigma[0] * sigma[0], sigma[1] * sigma[1], sigma[2] * sigma[2],
                                        sigma[3] * sigma[3])
                            .asDiagonal();
  }
  Expected<std::shared_ptr<const Submap>> a = SubmapCodec::ReadFile(files[0]);
  Expected<std::shared_ptr<const Submap>> b = SubmapCodec::ReadFile(files[1]);
  for (const auto* s : {&a, &b}) {
    if (!s->ok()) {
      std::fprintf(stderr, "cairn match: %s\n", s->status().ToString().c_str());
      return 1;
    }
  }
  const SubmapFeatureExtractor extractor({}, frame);
  const SubmapFeatures fa = extractor.Extract(**a), fb = extractor.Extract(**b);
  const SubmapMatchResult r = SubmapMatcher().Match(fa, fb, prior);

  JsonWriter j;
  j.BeginObject();
  j.Field("status", MatchStatusName(r.status));
  j.Field("reason", r.reason);
  j.Field("dof", r.dof);
  WriteFeatures(j, "a", files[0], fa);
  WriteFeatures(j, "b", files[1], fb);
  if (r.matched()) {
    WriteTransform(j, r);
    j.Key("covariance_order").BeginArray().String("x").String("y").String("z").String("yaw").EndArray();
    j.Key("covariance").BeginArray();
    for (int row = 0; row < 4; ++row) {
      j.BeginArray();
      for (int c = 0; c < 4; ++c) j.Number(r.covariance(row, c));
      j.EndArray();
    }
    j.EndArray();
  }
  j.Key("counts").BeginObject();
  j.Field("correspondences", r.correspondences).Field("clusters", r.clusters).Field("hypotheses", r.hypotheses);
  j.Field("gated_out", r.gated_out).Field("spread_rejected", r.spread_rejected).Field("refined", r.refined);
  j.Field("ransac_inliers", r.ransac_inliers).Field("icp_inliers", r.icp_inliers);
  j.Field("icp_rms", r.icp_rms).Field("icp_iterations", r.icp_iterations);
  j.Field("photometric_rejected", r.photometric_rejected).Field("grey_pairs", r.photometric.pairs);
  j.Field("searched", r.searched).Field("plane_hypotheses", r.plane_hypotheses);
  j.Field("line_hypotheses", r.line_hypotheses);
  j.Field("grey_correlation", r.photometric.ncc);  // null where the grey levels could not judge
  j.EndObject();
  j.Key("time_ms").BeginObject();
  j.Field("keypoints", fa.keypoint_ms + fb.keypoint_ms).Field("descriptors", fa.descriptor_ms + fb.descriptor_ms);
  j.Field("correspondences", r.times.correspondences_ms).Field("hough", r.times.hough_ms);
  j.Field("ransac", r.times.ransac_ms)
      .Field("icp", r.times.icp_ms)
      .Field("search", r.times.search_ms)
      .Field("planes", r.times.planes_ms)
      .Field("lines", r.times.lines_ms)
      .Field("match_total", r.times.total_ms);
  j.EndObject();
  j.EndObject();
  std::printf("%s\n", j.str().c_str());
  return 0;
}

}  // namespace cairn::tools
