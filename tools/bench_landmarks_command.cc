// cairn bench landmarks: the graph thread's cost of pairing the straight edges of cairnd runs'
// submaps into line landmarks, as the landmark stage pairs them: every two submaps whose origins
// lie within the stage's reach, placed at their true origins with a stated covariance. The
// association is timed beside the search of every pairing it replaces, in the same run, and its
// decisions are checked against that search. (Faces are few per submap; their pairing costs
// microseconds.)

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <numeric>
#include <string>
#include <vector>

#include "mapping/matching/line_associator.h"
#include "mapping/matching/testing/every_line_pairing.h"
#include "mapping/matching/testing/placements.h"
#include "tools/commands.h"
#include "tools/sample_median.h"
#include "tools/submap_truth.h"

namespace cairn::tools {
namespace {

using LandmarkClock = std::chrono::steady_clock;

double LandmarkMs(LandmarkClock::time_point a, LandmarkClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

bool SameDecisions(const std::vector<LineAssociation>& x, const std::vector<LineAssociation>& y) {
  if (x.size() != y.size()) return false;
  for (size_t i = 0; i < x.size(); ++i) {
    if (x[i].a != y[i].a || x[i].b != y[i].b || x[i].chi2 != y[i].chi2) return false;
  }
  return true;
}

void PrintLandmarkTimes(const char* name, const std::vector<double>& ms) {
  std::printf("  %-34s median %7.3f ms, p90 %7.3f ms, max %7.3f ms, sum %8.1f ms\n", name, Median(ms),
              NearestRankPercentile(ms, 0.9), NearestRankPercentile(ms, 1.0),
              std::accumulate(ms.begin(), ms.end(), 0.0));
}

}  // namespace

constexpr const char* kBenchLandmarksUsage =
    "usage: cairn bench landmarks OUT_DIR... [--sigma T,R (0.1,0.01)] [--reach M (40)] [--repeats N (3)]\n"
    "  OUT_DIR: cairnd output folders of simulated runs of one world (submaps/ with index.csv)\n"
    "  --sigma: each origin's standard deviation in translation (m) and rotation (rad) about its\n"
    "           true pose, as the graph's marginal covariances would give it\n"
    "  --reach: origins farther apart than this (xy, m) are not compared (matching.*_landmarks.\n"
    "           max_origin_distance)\n";

int RunBenchLandmarks(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchLandmarksUsage);
  std::vector<std::string> dirs;
  double sigma_t = 0.1, sigma_r = 0.01, reach = 40.0;
  int repeats = 3;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    std::vector<double> n;
    if (a == "--sigma" && i + 1 < args.args.size() && ParseNumberList(args.args[i + 1], &n) &&
        n.size() == 2 && n[0] > 0.0 && n[1] > 0.0) {
      sigma_t = n[0];
      sigma_r = n[1];
      ++i;
    } else if (a == "--reach" && i + 1 < args.args.size() && ParseNumberList(args.args[i + 1], &n) &&
               n.size() == 1 && n[0] > 0.0) {
      reach = n[0];
      ++i;
    } else if (a == "--repeats" && i + 1 < args.args.size() && ParseNumberList(args.args[i + 1], &n) &&
               n.size() == 1 && n[0] >= 1 && n[0] <= 100) {
      repeats = static_cast<int>(n[0]);
      ++i;
    } else if (!a.empty() && a[0] != '-') {
      dirs.push_back(a);
    } else {
      std::fputs(kBenchLandmarksUsage, stderr);
      return 2;
    }
  }
  if (dirs.empty()) {
    std::fputs(kBenchLandmarksUsage, stderr);
    return 2;
  }
  std::vector<SubmapWithTruth> submaps;
  for (const std::string& d : dirs) {
    if (Status s = ReadSubmapsWithTruth(d, &submaps); !s.ok()) {
      std::fprintf(stderr, "cairn bench landmarks: %s\n", s.ToString().c_str());
      return 1;
    }
  }
  const LineAssociationOptions line_options;
  const LineAssociator lines(line_options);
  std::vector<double> edges_per_submap;
  for (const SubmapWithTruth& s : submaps) {
    const std::vector<SubmapLine>& l = s.submap->structure().lines;
    edges_per_submap.push_back(static_cast<double>(
        std::count_if(l.begin(), l.end(), [&](const SubmapLine& x) { return lines.Eligible(x); })));
  }

  std::vector<double> bounded_ms, every_ms, ratios;
  size_t pairings = 0, beyond = 0, differing = 0, paired = 0;
  const double line_reach = line_options.gate_chi2 + line_options.ambiguity_chi2;
  for (size_t i = 0; i < submaps.size(); ++i) {
    for (size_t j = i + 1; j < submaps.size(); ++j) {
      const SubmapWithTruth &a = submaps[i], &b = submaps[j];
      const SubmapPlacement pa = testing::PlacedWithSigma(a.T_world_submap.ToIsometry(), sigma_t, sigma_r);
      const SubmapPlacement pb = testing::PlacedWithSigma(b.T_world_submap.ToIsometry(), sigma_t, sigma_r);
      if ((pa.T_world_submap.translation() - pb.T_world_submap.translation()).head<2>().norm() > reach)
        continue;
      const std::vector<SubmapLine>& la = a.submap->structure().lines;
      const std::vector<SubmapLine>& lb = b.submap->structure().lines;
      if (edges_per_submap[i] == 0.0 || edges_per_submap[j] == 0.0) continue;
      std::vector<double> bounded, every;
      std::vector<LineAssociation> fast, slow;
      for (int r = 0; r < repeats; ++r) {
        // Alternating which goes first, so that neither always finds the caches warm.
        for (int k = 0; k < 2; ++k) {
          const auto t0 = LandmarkClock::now();
          if ((k + r) % 2 == 0) {
            fast = lines.Associate(la, pa, lb, pb);
            bounded.push_back(LandmarkMs(t0, LandmarkClock::now()));
          } else {
            slow = testing::EveryLinePairing(lines, line_options, la, pa, lb, pb);
            every.push_back(LandmarkMs(t0, LandmarkClock::now()));
          }
        }
      }
      bounded_ms.push_back(Median(bounded));
      every_ms.push_back(Median(every));
      ratios.push_back(Median(every) / std::max(1e-6, Median(bounded)));
      differing += !SameDecisions(fast, slow);
      paired += fast.size();
      for (const SubmapLine& x : la) {
        if (!lines.Eligible(x)) continue;
        for (const SubmapLine& y : lb) {
          if (!lines.Eligible(y)) continue;
          ++pairings;
          beyond += lines.LowerBound(x, pa, y, pb) > line_reach;
        }
      }
    }
  }
  std::printf(
      "cairn bench landmarks: %zu submaps with true origins from %zu folder(s); origins placed with sigma "
      "%.3f m, %.4f rad; pairs within %.0f m; median of %d runs per pair\n",
      submaps.size(), dirs.size(), sigma_t, sigma_r, reach, repeats);
  if (bounded_ms.empty()) {
    std::printf("  no two submaps within reach both have an eligible edge: nothing to time\n");
    return 0;
  }
  std::printf("  eligible edges per submap: median %.0f, max %.0f\n", Median(edges_per_submap),
              NearestRankPercentile(edges_per_submap, 1.0));
  std::printf("  line association, per pair of submaps (%zu pairs, %zu pairings of edges):\n",
              bounded_ms.size(), pairings);
  PrintLandmarkTimes("bounded (LineAssociator)", bounded_ms);
  PrintLandmarkTimes("baseline: every pairing's distance", every_ms);
  std::printf("  ratio baseline / bounded, per pair: median %.1f; of the sums %.1f\n", Median(ratios),
              std::accumulate(every_ms.begin(), every_ms.end(), 0.0) /
                  std::max(1e-6, std::accumulate(bounded_ms.begin(), bounded_ms.end(), 0.0)));
  std::printf("  pairings put beyond reach (chi2 %.2f) by the bound alone: %zu of %zu (%.1f %%)\n",
              line_reach, beyond, pairings,
              100.0 * static_cast<double>(beyond) / static_cast<double>(std::max<size_t>(1, pairings)));
  std::printf("  decisions: %zu edges paired; %zu pairs of submaps decided otherwise than by the baseline\n",
              paired, differing);
  return differing == 0 ? 0 : 1;
}

}  // namespace cairn::tools
