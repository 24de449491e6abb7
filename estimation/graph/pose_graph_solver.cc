#include "estimation/graph/pose_graph_solver.h"

#include <chrono>
#include <cmath>
#include <cstdio>

#include "estimation/graph/chordal_initializer.h"
#include "estimation/graph/noise_scale.h"
#include "estimation/graph/pairwise_consistency.h"
#include "estimation/graph/pose_factors.h"

namespace cairn {
namespace {

double Seconds(std::chrono::steady_clock::time_point since) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - since).count();
}

// Squared whitened residual beyond which GNC rejects a closure: chi-square, 6 dof, 99.9 %.
constexpr double kGncDefaultThreshold = 22.46;
// Relative cost change that ends a GNC round (the final solve converges fully).
constexpr double kGncRoundTolerance = 1e-6;
// Loop closures whose Cauchy weight is below kPruneWeight are left out of a Cauchy solve (their
// pull at most 0.2 % of the largest); which closures those are is revisited every
// kPruneIterations iterations.
constexpr double kPruneWeight = 1e-6;
constexpr int kPruneIterations = 5;
// After PCM: the chi-square probability beyond which a kept closure's residual rejects it, and
// how many screening solves at most.
constexpr double kResidualConfidence = 0.999;
constexpr int kResidualRounds = 6;

// The graph of the edges `keep` marks, same vertices in the same order.
PoseGraph KeptEdges(const PoseGraph& graph, const std::vector<bool>& keep) {
  PoseGraph kept;
  for (size_t v = 0; v < graph.num_vertices(); ++v) kept.SetVertex(graph.ids()[v], graph.poses()[v]);
  for (size_t k = 0; k < graph.edges().size(); ++k) {
    if (keep[k]) kept.AddEdge(graph.edges()[k]);
  }
  kept.set_has_initial_estimate(graph.has_initial_estimate());
  kept.set_first_indefinite(graph.first_indefinite());
  return kept;
}

// Squared whitened geodesic residual of every loop closure of `graph` at its vertex estimates.
std::vector<double> LoopClosureChi2(const PoseGraph& graph) {
  std::vector<double> r2;
  for (const auto& e : graph.edges()) {
    if (!IsLoopClosure(e)) continue;
    const Vector6d r = GeodesicError(graph.poses()[graph.Find(e.from)], graph.poses()[graph.Find(e.to)], e.T_from_to);
    r2.push_back(r.dot(EffectiveInformation(e) * r));
  }
  return r2;
}

// The noise scale (noise_scale.h) as the fixed point s = F(s) of F(s), the estimate from the loop
// closures' residuals at the Cauchy solution with c = sqrt(s) (the loss's knee at a squared
// residual of s, 1 in the units of the noise): a loss too wide lets false closures drag true ones
// off (F(s) high), one too narrow leaves true closures unsatisfied (also high) or nearly fits the
// true ones (low), and F is found decreasing around its fixed point on every graph tried: the
// fixed point is bracketed from s = 1 and F(1), then bisected in log s to a factor of two (or
// until a scale's estimate is within a factor of two of it). Solves
// of `robust_graph`, from odometry, each warm-started at the last; it is left at the last one.
// The search runs twice: first with solves stopped at a relative cost change of
// kCoarseTolerance (far from the fixed point, and while the false closures still carry weight,
// every iteration is slow and only the estimate's factor of two matters), then from its result
// with converged solves, which decide.
Expected<double> RobustNoiseScale(PoseGraph& robust_graph, const PoseGraphSolverOptions& options) {
  constexpr int kSolves = 10;
  constexpr double kCoarseTolerance = 1e-3;
  PoseGraphSolverOptions robust = options;
  robust.outliers = PoseGraphSolverOptions::Outliers::kNone;
  if (options.init != PoseGraphSolverOptions::Init::kFile) robust.init = PoseGraphSolverOptions::Init::kOdometry;
  robust.verbose = false;
  const int dof = robust_graph.planar() ? 3 : 6;
  int solves = 0;
  auto estimate_at = [&](double scale) -> Expected<double> {
    robust.cauchy_c = std::sqrt(scale);
    auto s = SolvePoseGraph(robust_graph, robust);
    if (!s.ok()) return s.status();
    robust.init = PoseGraphSolverOptions::Init::kFile;
    robust_graph.set_has_initial_estimate(true);
    ++solves;
    const double next = EstimateNoiseScale(LoopClosureChi2(robust_graph), dof, kResidualConfidence).scale;
    if (options.verbose) {
      std::fprintf(stderr, "noise scale: Cauchy c^2 %.4g gives %.4g (tolerance %.0e: %d iterations, %.2f s)\n", scale,
                   next, robust.function_tolerance, s->iterations, s->solve_seconds);
    }
    return next;
  };
  // g(s) = log F(s) - log s: positive below the fixed point, negative above.
  const auto near_fixed_point = [](double s, double f) { return f > 0.5 * s && f < 2.0 * s; };
  auto search = [&](double a) -> Expected<double> {
    auto fa = estimate_at(a);
    if (!fa.ok()) return fa.status();
    double b = *fa;
    while (solves < kSolves) {
      if (near_fixed_point(a, b)) return std::sqrt(a * b);
      auto fb = estimate_at(b);
      if (!fb.ok()) return fb.status();
      if (near_fixed_point(b, *fb)) return std::sqrt(b * *fb);
      if ((*fa > a) != (*fb > b)) break;  // bracketed
      a = b;
      fa = fb;
      b = *fb;
    }
    // Bisection of [a, b] in log s.
    while (solves < kSolves && std::abs(std::log(b / a)) > std::log(2.0)) {
      const double m = std::sqrt(a * b);
      auto fm = estimate_at(m);
      if (!fm.ok()) return fm.status();
      if (near_fixed_point(m, *fm)) return std::sqrt(m * *fm);
      ((*fm > m) == (*fa > a) ? a : b) = m;
    }
    return std::sqrt(a * b);
  };
  robust.function_tolerance = std::max(options.function_tolerance, kCoarseTolerance);
  auto coarse = search(1.0);
  if (!coarse.ok()) return coarse.status();
  robust.function_tolerance = std::max(options.function_tolerance, 1e-6);
  return search(*coarse);
}

// GNC with the estimated noise scale (see SolvePoseGraph in the header).
Expected<PoseGraphSolveSummary> SolveWithEstimatedScale(PoseGraph& graph, const PoseGraphSolverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PoseGraph robust = graph;
  auto scale = RobustNoiseScale(robust, options);
  if (!scale.ok()) return scale.status();
  const double scale_seconds = Seconds(start);
  PoseGraphSolverOptions gnc = options;
  gnc.noise_scale = *scale;
  // GNC's warm start is the Cauchy solve at that scale: from the last one there, not from odometry.
  const bool had_estimate = graph.has_initial_estimate();
  graph.poses() = robust.poses();
  graph.set_has_initial_estimate(true);
  gnc.init = PoseGraphSolverOptions::Init::kFile;
  auto summary = SolvePoseGraph(graph, gnc);
  graph.set_has_initial_estimate(had_estimate);
  if (!summary.ok()) return summary.status();
  summary->scale_seconds = scale_seconds;
  summary->init_seconds += scale_seconds;
  return summary;
}

// PCM, then the ordinary solve of the graph without the rejected closures (its chordal
// initialization no longer pulled by them). PCM keeps false closures whose cycles all run through
// long, uncertain odometry: they agree with every closure within its drift. At the solution of
// the kept edges (with a Cauchy loss, so that they pull little) they stand out by their residual:
// closures whose squared whitened residual exceeds the chi-square quantile are dropped and the
// rest solved again. That quantile is in units of the closures' own noise: with noise_scale 0,
// the estimate from their residuals (RobustNoiseScale over the kept edges), not the cycles'
// scale, which answers another question (the cycles' spread, odometry included) and on intel
// with 20 % false closures is ten times the closures' (false closures then pass the screen).
Expected<PoseGraphSolveSummary> SolveKeptEdges(PoseGraph& graph, const PoseGraphSolverOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  PairwiseConsistencyOptions pcm_options;
  pcm_options.confidence = options.pcm_confidence;
  pcm_options.noise_scale = options.noise_scale;  // 0: from the cycles
  auto pcm = FindConsistentLoopClosures(graph, pcm_options);
  if (!pcm.ok()) return pcm.status();
  const double pcm_seconds = Seconds(start);
  std::vector<bool> keep = pcm->keep;
  double scale = pcm->noise_scale;
  if (options.noise_scale <= 0.0) {
    PoseGraph kept = KeptEdges(graph, keep);
    auto residual_scale = RobustNoiseScale(kept, options);
    if (!residual_scale.ok()) return residual_scale.status();
    scale = *residual_scale;
  }
  PoseGraphSolverOptions inner = options;
  inner.outliers = PoseGraphSolverOptions::Outliers::kNone;
  const double threshold = scale * ChiSquareQuantile(kResidualConfidence, graph.planar() ? 3 : 6);
  // Cauchy scale at the threshold: true closures keep nearly full weight, the rest pull little.
  PoseGraphSolverOptions screen = inner;
  screen.cauchy_c = options.cauchy_c > 0.0 ? options.cauchy_c : std::sqrt(threshold);
  int screened = 0;
  for (int round = 0; round < kResidualRounds; ++round) {
    PoseGraph kept = KeptEdges(graph, keep);
    auto s = SolvePoseGraph(kept, screen);
    if (!s.ok()) return s.status();
    bool dropped = false;
    for (size_t k = 0, j = 0; k < graph.edges().size(); ++k) {
      if (!keep[k]) continue;
      const auto& e = kept.edges()[j++];
      if (!IsLoopClosure(e)) continue;
      const Vector6d r = GeodesicError(kept.poses()[kept.Find(e.from)], kept.poses()[kept.Find(e.to)], e.T_from_to);
      if (r.dot(EffectiveInformation(e) * r) > threshold) {
        keep[k] = false;
        dropped = true;
        ++screened;
      }
    }
    if (!dropped) break;
  }
  PoseGraph kept = KeptEdges(graph, keep);
  auto summary = SolvePoseGraph(kept, inner);
  if (!summary.ok()) return summary.status();
  graph.poses() = kept.poses();  // same vertex order
  summary->outlier_seconds = pcm_seconds;
  summary->init_seconds += pcm_seconds;
  summary->noise_scale = scale;
  for (size_t k = 0; k < keep.size(); ++k) {
    if (!keep[k]) summary->rejected.push_back(k);
  }
  summary->rejected_edges = static_cast<int>(summary->rejected.size());
  summary->solve_seconds = Seconds(start) - summary->init_seconds;
  if (options.verbose) {
    std::fprintf(stderr,
                 "pcm: %d of %d loop closures rejected, %d groups, %lld pairs, threshold %.3f, %s, %.3f s; "
                 "%d more by residual (noise scale %.4g)\n",
                 pcm->rejected, pcm->loop_closures, pcm->groups, static_cast<long long>(pcm->pairs_tested),
                 pcm->threshold, pcm->exact ? "exact" : "greedy", pcm_seconds, screened, scale);
  }
  return summary;
}

}  // namespace

bool IsLoopClosure(const PoseGraphEdge& e) { return !IsOdometryEdge(e); }

Expected<PoseGraphSolveSummary> SolvePoseGraph(PoseGraph& graph, const PoseGraphSolverOptions& options) {
  using Options = PoseGraphSolverOptions;
  if (options.init == Options::Init::kFile && !graph.has_initial_estimate()) {
    return FailedPreconditionError("--init file: the graph has no vertex estimates");
  }
  if (options.objective == Options::Objective::kGeodesic && graph.indefinite_edges() > 0) {
    return FailedPreconditionError(
        std::to_string(graph.indefinite_edges()) + " of " + std::to_string(graph.edges().size()) +
        " edges have information that is not positive definite (first at " +
        (graph.first_indefinite().empty() ? std::string("?") : graph.first_indefinite()) +
        "): the geodesic objective needs it; the SE-Sync objective uses only their "
        "isotropic precisions");
  }
  if (options.outliers == Options::Outliers::kGnc && options.noise_scale <= 0.0 && options.cauchy_c <= 0.0) {
    return SolveWithEstimatedScale(graph, options);
  }
  if (options.outliers == Options::Outliers::kPcm) return SolveKeptEdges(graph, options);
  PoseGraphSolveSummary summary;
  const auto start = std::chrono::steady_clock::now();
  const bool gnc = options.outliers == Options::Outliers::kGnc;
  // GNC starts from odometry: a chordal start over all closures is already bent by the false ones.
  if (options.init == Options::Init::kOdometry || !graph.has_initial_estimate() ||
      (gnc && options.init == Options::Init::kChordal)) {
    InitializeFromSpanningTree(graph);
  }
  if (options.init == Options::Init::kChordal && !gnc) CAIRN_RETURN_IF_ERROR(InitializeChordal(graph));
  // GNC's threshold in the units of the actual noise, unless the caller gave it.
  if (gnc && options.cauchy_c <= 0.0 && options.noise_scale > 0.0) summary.noise_scale = options.noise_scale;
  summary.init_seconds = Seconds(start);
  summary.initial_sesync_cost = SeSyncCost(graph);

  const size_t n = graph.num_vertices();
  std::vector<double> blocks(7 * n);
  for (size_t v = 0; v < n; ++v) PoseToBlock(graph.poses()[v], &blocks[7 * v]);

  ceres::Problem::Options problem_options;
  problem_options.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  problem_options.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(problem_options);
  const auto manifold = MakePoseManifold();
  std::unique_ptr<ceres::LossFunction> cauchy;
  if (options.cauchy_c > 0.0) cauchy = std::make_unique<ceres::CauchyLoss>(options.cauchy_c);
  // GNC weights live in ScaledLoss wrappers so they can change between rounds.
  std::vector<std::unique_ptr<ceres::LossFunctionWrapper>> weights;
  std::vector<ceres::ResidualBlockId> residuals;
  std::vector<int> weight_of_edge(graph.edges().size(), -1);
  for (size_t k = 0; k < graph.edges().size(); ++k) {
    const auto& e = graph.edges()[k];
    ceres::CostFunction* cost =
        options.objective == Options::Objective::kSeSync
            ? ChordalResidual::Create(e.T_from_to, e.kappa, e.tau)
            : RelativePoseResidual::Create(e.T_from_to, e.information);
    ceres::LossFunction* loss = nullptr;
    if (IsLoopClosure(e)) {
      if (options.outliers == Options::Outliers::kGnc) {
        // The first solve uses a Cauchy loss (c = 1 in units of the noise scale): a warm start
        // that outliers do not drag far, which the local solver needs before GNC's rounds (its
        // convex start is only convex for a global solver).
        weights.push_back(std::make_unique<ceres::LossFunctionWrapper>(
            new ceres::CauchyLoss(std::sqrt(summary.noise_scale)), ceres::TAKE_OWNERSHIP));
        weight_of_edge[k] = static_cast<int>(weights.size()) - 1;
        loss = weights.back().get();
      } else {
        loss = cauchy.get();
      }
    }
    residuals.push_back(problem.AddResidualBlock(cost, loss, &blocks[7 * graph.Find(e.from)],
                                                 &blocks[7 * graph.Find(e.to)]));
  }
  const std::vector<int> component = graph.Components(&summary.components);
  std::vector<bool> anchored(static_cast<size_t>(summary.components), false);
  for (size_t v = 0; v < n; ++v) {
    if (!problem.HasParameterBlock(&blocks[7 * v])) continue;
    problem.SetManifold(&blocks[7 * v], manifold.get());
    if (!anchored[static_cast<size_t>(component[v])]) {
      anchored[static_cast<size_t>(component[v])] = true;
      problem.SetParameterBlockConstant(&blocks[7 * v]);  // gauge of this component
    }
  }

  ceres::Solver::Options solver;
  solver.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  solver.sparse_linear_algebra_library_type = ceres::SUITE_SPARSE;
  solver.max_num_iterations = static_cast<int>(options.max_iterations);
  solver.function_tolerance = options.function_tolerance > 0.0 ? options.function_tolerance
                              : options.objective == Options::Objective::kSeSync ? 1e-6
                                                                                 : 1e-10;
  solver.gradient_tolerance = 1e-14;
  solver.parameter_tolerance = 1e-10;
  // SE-Sync's objective: dogleg takes the Gauss-Newton step whenever it stays in the trust region,
  // which on these graphs needs far fewer iterations than Levenberg-Marquardt to the same
  // optimum (sphere2500 2 instead of 7, intel 2 instead of 8, city10000 2 instead of 9).
  if (options.objective == Options::Objective::kSeSync) solver.trust_region_strategy_type = ceres::DOGLEG;
  solver.num_threads = static_cast<int>(options.threads);
  solver.minimizer_progress_to_stdout = options.verbose;

  // Squared raw (unweighted) residual of every loop closure at the current blocks.
  std::vector<double> r2(graph.edges().size(), 0.0);
  double max_r2 = 0.0;
  auto evaluate = [&] {
    max_r2 = 0.0;
    std::vector<double*> params;
    std::vector<double> r;
    for (size_t k = 0; k < residuals.size(); ++k) {
      if (!IsLoopClosure(graph.edges()[k])) continue;
      const ceres::CostFunction* f = problem.GetCostFunctionForResidualBlock(residuals[k]);
      problem.GetParameterBlocksForResidualBlock(residuals[k], &params);
      r.resize(static_cast<size_t>(f->num_residuals()));
      f->Evaluate(params.data(), r.data(), nullptr);
      double sum = 0.0;
      for (double x : r) sum += x * x;
      r2[k] = sum;
      max_r2 = std::max(max_r2, sum);
    }
  };
  // Solves see only the active loop closures (and every odometry edge): random false closures
  // are long edges that fill the Cholesky factor in, so leaving out those that pull (next to)
  // nothing keeps the solves as sparse as the inlier graph.
  std::vector<bool> active(graph.edges().size(), true);
  auto solve_active = [&](const ceres::Solver::Options& o, ceres::Solver::Summary* s) {
    ceres::Problem::Options po;
    po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
    ceres::Problem subset(po);
    std::vector<double*> params;
    for (size_t k = 0; k < residuals.size(); ++k) {
      if (!active[k]) continue;
      problem.GetParameterBlocksForResidualBlock(residuals[k], &params);
      subset.AddResidualBlock(const_cast<ceres::CostFunction*>(problem.GetCostFunctionForResidualBlock(residuals[k])),
                              const_cast<ceres::LossFunction*>(problem.GetLossFunctionForResidualBlock(residuals[k])),
                              params);
    }
    for (size_t v = 0; v < n; ++v) {
      double* b = &blocks[7 * v];
      if (!subset.HasParameterBlock(b)) continue;
      subset.SetManifold(b, manifold.get());
      if (problem.IsParameterBlockConstant(b)) subset.SetParameterBlockConstant(b);
    }
    ceres::Solve(o, &subset, s);
  };

  ceres::Solver::Summary ceres_summary;
  // Cauchy scale of the closures' loss in the first solve (GNC's warm start is one); 0 = none.
  const double cauchy_c2 = gnc ? summary.noise_scale : options.cauchy_c * options.cauchy_c;
  if (cauchy_c2 > 0.0) {
    // The Cauchy loss weighs a closure by 1 / (1 + r2 / c^2) and its pull on the solution (the
    // gradient) is at most 2 sqrt(weight) of the largest any closure exerts: closures below
    // kPruneWeight are left out of the solve, in chunks of kPruneIterations iterations, after each
    // of which every closure's residual is evaluated again (one that comes close re-enters).
    const double prune_r2 = cauchy_c2 * (1.0 / kPruneWeight - 1.0);
    auto prune = [&] {
      evaluate();
      bool changed = false;
      for (size_t k = 0; k < residuals.size(); ++k) {
        if (!IsLoopClosure(graph.edges()[k])) continue;
        const bool a = r2[k] <= prune_r2;
        changed = changed || a != active[k];
        active[k] = a;
      }
      return changed;
    };
    prune();
    int chunks = 0;
    summary.iterations = 0;
    ceres::Solver::Options chunk = solver;
    // GNC's rounds move on from its warm start: it needs no more precision than a round.
    if (gnc) chunk.function_tolerance = std::max(solver.function_tolerance, kGncRoundTolerance);
    for (;;) {
      chunk.max_num_iterations =
          std::max(1, std::min(kPruneIterations, solver.max_num_iterations - summary.iterations));
      solve_active(chunk, &ceres_summary);
      // The next chunk goes on with the trust region this one ended with.
      if (!ceres_summary.iterations.empty()) {
        chunk.initial_trust_region_radius = ceres_summary.iterations.back().trust_region_radius;
      }
      summary.iterations += static_cast<int>(ceres_summary.iterations.size()) - 1;
      if (options.verbose) std::fprintf(stderr, "%s\n", ceres_summary.FullReport().c_str());
      const bool changed = prune();
      const bool converged = ceres_summary.termination_type != ceres::NO_CONVERGENCE;
      if ((converged && !changed) || summary.iterations >= solver.max_num_iterations ||
          ++chunks >= solver.max_num_iterations) {
        break;
      }
    }
  } else {
    ceres::Solve(solver, &problem, &ceres_summary);
    summary.iterations = static_cast<int>(ceres_summary.iterations.size()) - 1;
    if (options.verbose) std::fprintf(stderr, "%s\n", ceres_summary.FullReport().c_str());
  }
  summary.termination = ceres_summary.BriefReport();
  if (options.outliers == Options::Outliers::kGnc) {
    // Graduated non-convexity with the truncated-least-squares surrogate (Yang et al. 2020):
    // threshold cbar^2 on the squared whitened residual, mu grows until the weights are binary.
    const double cbar2 =
        options.cauchy_c > 0.0 ? options.cauchy_c * options.cauchy_c : kGncDefaultThreshold * summary.noise_scale;
    // Rounds only follow the weights; the final solve converges fully. A closure of zero weight
    // leaves the solves.
    ceres::Solver::Options round_solver = solver;
    round_solver.max_num_iterations = static_cast<int>(std::min(options.gnc_round_iterations, options.max_iterations));
    round_solver.function_tolerance = std::max(solver.function_tolerance, kGncRoundTolerance);
    evaluate();
    // mu starts where the surrogate is convex for every residual (Yang et al.) or, when later,
    // where a closure at the threshold keeps the weight the Cauchy warm start gave it,
    // 1 / (1 + cbar2 / c^2): w(cbar2) = sqrt(mu (mu + 1)) - mu, so mu = w^2 / (1 - 2 w). From the
    // convex start every closure weighs far less than the odometry: the first rounds drag the warm
    // start back towards dead reckoning and keep every false closure (and the fill-in of the
    // Cholesky factor it causes) in the solves for dozens of rounds.
    const double warm_weight = 1.0 / (1.0 + cbar2 / summary.noise_scale);
    double mu = cbar2 / std::max(2.0 * max_r2 - cbar2, 1e-12);
    if (warm_weight < 0.5) mu = std::max(mu, warm_weight * warm_weight / (1.0 - 2.0 * warm_weight));
    for (int round = 0; round < 100 && mu < 1e6; ++round) {
      bool binary = true;  // every weight already 0 or 1: further rounds change nothing
      for (size_t k = 0; k < residuals.size(); ++k) {
        if (weight_of_edge[k] < 0) continue;
        const double s = r2[k];
        double w;
        if (s >= (mu + 1.0) / mu * cbar2) {
          w = 0.0;
        } else if (s <= mu / (mu + 1.0) * cbar2) {
          w = 1.0;
        } else {
          w = std::sqrt(cbar2 * mu * (mu + 1.0) / s) - mu;
          binary = false;
        }
        active[k] = w > 0.0;
        weights[static_cast<size_t>(weight_of_edge[k])]->Reset(
            new ceres::ScaledLoss(nullptr, std::max(w, 1e-12), ceres::TAKE_OWNERSHIP), ceres::TAKE_OWNERSHIP);
      }
      if (binary && round > 0) break;
      ceres::Solver::Summary round_summary;
      solve_active(round_solver, &round_summary);
      summary.iterations += static_cast<int>(round_summary.iterations.size()) - 1;
      evaluate();
      mu *= 1.4;
    }
    // Final solve with binary weights: the optimum of the graph without the rejected closures.
    for (size_t k = 0; k < residuals.size(); ++k) {
      if (weight_of_edge[k] < 0) continue;
      const bool rejected = r2[k] > cbar2;
      summary.rejected_edges += rejected ? 1 : 0;
      if (rejected) summary.rejected.push_back(k);
      active[k] = !rejected;
      weights[static_cast<size_t>(weight_of_edge[k])]->Reset(
          new ceres::ScaledLoss(nullptr, rejected ? 1e-12 : 1.0, ceres::TAKE_OWNERSHIP), ceres::TAKE_OWNERSHIP);
    }
    ceres::Solver::Summary final_summary;
    solve_active(solver, &final_summary);
    summary.iterations += static_cast<int>(final_summary.iterations.size()) - 1;
  }
  summary.solve_seconds = Seconds(start) - summary.init_seconds;
  for (size_t v = 0; v < n; ++v) graph.poses()[v] = BlockToPose(&blocks[7 * v]);
  summary.sesync_cost = SeSyncCost(graph);
  summary.geodesic_chi2 = GeodesicChi2(graph);
  return summary;
}

}  // namespace cairn
