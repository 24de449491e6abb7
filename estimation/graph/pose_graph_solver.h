#pragma once
// Batch solve of a PoseGraph with Ceres (`cairn graph solve`): initialization, then
// Levenberg-Marquardt on SE(3) in either the full-information geodesic objective or the isotropic
// SE-Sync objective, optionally with a Cauchy loss on loop closures and outlier rejection.

#include <string>
#include <vector>

#include "common/options_visitor.h"
#include "common/status.h"
#include "estimation/graph/pose_graph.h"

namespace cairn {

struct PoseGraphSolverOptions {
  enum class Objective { kGeodesic, kSeSync };
  enum class Init { kChordal, kOdometry, kFile };
  // kPcm: pairwise-consistency rejection of loop closures, then the solve of the kept edges.
  // kGnc: graduated non-convexity (truncated least squares) from the odometry initialization.
  enum class Outliers { kNone, kPcm, kGnc };

  Objective objective = Objective::kGeodesic;
  Init init = Init::kChordal;
  Outliers outliers = Outliers::kNone;
  // Factor s by which the actual noise variance exceeds the information's: the outlier thresholds
  // (PCM's, GNC's and its warm-start Cauchy scale) are multiplied by it. 0 = estimated (see
  // SolvePoseGraph); 1 = the information as given. An explicit cauchy_c with GNC is used as given.
  double noise_scale = 0.0;
  // Cauchy scale c (eq. 4.10) on loop closures (edges other than i -> i+1 of one robot); 0 = none.
  // With GNC, c^2 is the truncation threshold on the squared whitened residual (default 22.46
  // times the noise scale).
  double cauchy_c = 0.0;
  int64_t max_iterations = 200;
  // Probability that every pair of true loop closures passes the pairwise-consistency test (kPcm).
  double pcm_confidence = 0.99;
  // Levenberg-Marquardt iterations per GNC round: each round only tracks the changed weights.
  int64_t gnc_round_iterations = 10;
  // Relative cost change that ends the solve; 0 = per objective: 1e-10 for the geodesic one
  // (quadratic convergence, one more iteration at most), 1e-6 for SE-Sync's (2-3 iterations on
  // four of the five standard graphs; parking-garage converges linearly and needs 24 iterations
  // for 6e-6 relative to its optimum, 93 for 1e-10).
  double function_tolerance = 0.0;
  int64_t threads = 1;
  bool verbose = false;  // Ceres progress and report on stderr

  void Visit(OptionsVisitor& v) {
    v.Choice("objective", objective, {{"geodesic", Objective::kGeodesic}, {"sesync", Objective::kSeSync}});
    v.Choice("init", init, {{"chordal", Init::kChordal}, {"odometry", Init::kOdometry}, {"file", Init::kFile}});
    v.Choice("outliers", outliers, {{"none", Outliers::kNone}, {"pcm", Outliers::kPcm}, {"gnc", Outliers::kGnc}});
    v.Number("noise_scale", noise_scale, 0.0, 1e12, "variance ratio (0 = estimated)");
    v.Number("cauchy_c", cauchy_c, 0.0, 1e6, "sqrt(chi2)");
    v.Integer("max_iterations", max_iterations, 1, 100000, "iterations");
    v.Number("pcm_confidence", pcm_confidence, 0.5, 0.999999, "probability");
    v.Integer("gnc_round_iterations", gnc_round_iterations, 1, 100000, "iterations");
    v.Number("function_tolerance", function_tolerance, 0.0, 1.0, "relative");
    v.Integer("threads", threads, 1, 64, "threads");
    v.Flag("verbose", verbose);
  }
};

struct PoseGraphSolveSummary {
  double sesync_cost = 0.0;      // SE-Sync objective at the solution (no 1/2)
  double geodesic_chi2 = 0.0;    // full-information geodesic chi-square at the solution
  double initial_sesync_cost = 0.0;
  int iterations = 0;
  double init_seconds = 0.0;
  double solve_seconds = 0.0;
  int components = 0;
  int rejected_edges = 0;        // loop closures given zero weight by outlier rejection
  std::vector<size_t> rejected;  // their edge indices, ascending
  double outlier_seconds = 0.0;  // of the pairwise-consistency search (part of init_seconds)
  double noise_scale = 1.0;      // the thresholds' factor, given or estimated
  double scale_seconds = 0.0;    // of its estimate's Cauchy solves (part of init_seconds)
  std::string termination;
};

// Loop closure: any edge other than robot odometry (consecutive indices of one robot).
bool IsLoopClosure(const PoseGraphEdge& e);

// With kPcm the costs in the summary are those of the kept edges.
// Estimated noise scale (GNC with noise_scale 0 and no cauchy_c): s such that the estimate of
// noise_scale.h from the loop closures' residuals at the Cauchy solution with c = sqrt(s) is s
// again (to a factor of two; a few Cauchy solves), then GNC with s. Not again at GNC's own
// solution: from odometry, GNC's rounds with a threshold at the bare inlier residuals of the
// final solution drop true closures that intermediate solutions leave far off. With PCM,
// noise_scale 0 estimates the cycles' scale from the cycles (pairwise_consistency.h) and the
// scale of the residual screen that follows it (see SolveKeptEdges) from the kept closures'
// residuals, as for GNC.
// Solves with a Cauchy loss on the closures (cauchy_c, the noise scale's, GNC's warm start) leave
// out the closures whose Cauchy weight is below 1e-6 (revisited every 5 iterations): random false
// closures fill the Cholesky factor in and make every iteration slow. GNC's rounds start where a
// closure at the threshold keeps the weight the Cauchy warm start gave it, not at the convex
// surrogate (where every closure weighs far less than odometry).
Expected<PoseGraphSolveSummary> SolvePoseGraph(PoseGraph& graph, const PoseGraphSolverOptions& options);

}  // namespace cairn
