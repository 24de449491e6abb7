// cairn graph solve | replay | inject: pose-graph back-end on standard g2o files.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cmath>
#include <cstdlib>
#include <random>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "estimation/graph/g2o_io.h"
#include "estimation/graph/graph_replay.h"
#include "estimation/graph/graph_worker.h"
#include "estimation/graph/pose_graph_solver.h"
#include "estimation/graph/slam_graph.h"
#include "estimation/math/ordered_draws.h"
#include "estimation/math/so3.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr const char* kSolveUsage =
    "usage: cairn graph solve IN.g2o|DIR [--out OUT.g2o] [--objective geodesic|sesync]\n"
    "                         [--init chordal|odometry|file] [--loss none|cauchy:C]\n"
    "                         [--outliers none|pcm|gnc] [--pcm-confidence P (probability that all true pairs "
    "pass, 0.99)]\n"
    "                         [--noise-scale auto|S (outlier thresholds in units of the estimated noise,\n"
    "                          or of S times the variance the information states; auto)]\n"
    "                         [--injected-after N (edges from index N on are false: prints recall)]\n"
    "                         [--threads N] [--verbose]\n"
    "                         [--project-information (information that is not positive definite:\n"
    "                          use the nearest positive-definite matrix; else only --objective sesync takes "
    "it)]\n"
    "                         [--tolerance REL (relative cost change that ends the solve)]\n"
    "                         [--reference SOLVED.g2o (prints the ATE against its vertices)]\n";

bool ParseSolveArgs(const CommandArgs& args, std::string& in, std::string& out, std::string& reference,
                    long long& injected_after, bool& project, PoseGraphSolverOptions& o) {
  using O = PoseGraphSolverOptions;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    const std::string v = has_value ? args.args[i + 1] : "";
    if (a == "--verbose") {
      o.verbose = true;
      continue;
    }
    if (a == "--project-information") {
      project = true;
      continue;
    }
    if (a.rfind("--", 0) != 0) {
      if (!in.empty()) return false;
      in = a;
      continue;
    }
    if (!has_value) return false;
    ++i;
    if (a == "--out") {
      out = v;
    } else if (a == "--objective" && (v == "geodesic" || v == "sesync")) {
      o.objective = v == "sesync" ? O::Objective::kSeSync : O::Objective::kGeodesic;
    } else if (a == "--init" && (v == "chordal" || v == "odometry" || v == "file")) {
      o.init = v == "chordal" ? O::Init::kChordal : v == "odometry" ? O::Init::kOdometry : O::Init::kFile;
    } else if (a == "--loss" && v == "none") {
      o.cauchy_c = 0.0;
    } else if (a == "--loss" && v.rfind("cauchy:", 0) == 0) {
      char* end = nullptr;
      o.cauchy_c = std::strtod(v.c_str() + 7, &end);
      if (*end != '\0' || !(o.cauchy_c > 0.0)) return false;
    } else if (a == "--outliers" && (v == "none" || v == "pcm" || v == "gnc")) {
      o.outliers = v == "gnc" ? O::Outliers::kGnc : v == "pcm" ? O::Outliers::kPcm : O::Outliers::kNone;
    } else if (a == "--noise-scale") {
      o.noise_scale = v == "auto" ? 0.0 : std::atof(v.c_str());
      if (!(o.noise_scale > 0.0) && v != "auto") return false;
    } else if (a == "--pcm-confidence") {
      o.pcm_confidence = std::atof(v.c_str());
      if (!(o.pcm_confidence >= 0.5 && o.pcm_confidence < 1.0)) return false;
    } else if (a == "--injected-after") {
      char* end = nullptr;
      injected_after = std::strtoll(v.c_str(), &end, 10);
      if (*end != '\0' || injected_after < 0) return false;
    } else if (a == "--tolerance") {
      o.function_tolerance = std::atof(v.c_str());
      if (!(o.function_tolerance > 0.0 && o.function_tolerance < 1.0)) return false;
    } else if (a == "--reference") {
      reference = v;
    } else if (a == "--threads") {
      o.threads = std::atoi(v.c_str());
      if (o.threads < 1) return false;
    } else {
      return false;
    }
  }
  return !in.empty();
}

// RMSE of vertex positions after the rigid alignment (no scale) of `g` onto `ref`, over the
// vertices both share.
double AbsoluteTrajectoryError(const PoseGraph& g, const PoseGraph& ref) {
  std::vector<Eigen::Vector3d> a, b;
  for (size_t i = 0; i < g.num_vertices(); ++i) {
    if (!ref.HasVertex(g.ids()[i])) continue;
    a.push_back(g.poses()[i].t);
    b.push_back(ref.poses()[ref.Find(g.ids()[i])].t);
  }
  if (a.size() < 3) return -1.0;
  Eigen::Matrix3Xd A(3, a.size()), B(3, b.size());
  for (size_t i = 0; i < a.size(); ++i) {
    A.col(static_cast<long>(i)) = a[i];
    B.col(static_cast<long>(i)) = b[i];
  }
  const Eigen::Matrix4d T = Eigen::umeyama(A, B, false);
  const Eigen::Matrix3Xd aligned = (T.topLeftCorner<3, 3>() * A).colwise() + T.topRightCorner<3, 1>();
  return std::sqrt((aligned - B).colwise().squaredNorm().mean());
}

}  // namespace

int RunGraphSolve(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kSolveUsage);
  std::string in, out, reference;
  long long injected_after = -1;
  PoseGraphSolverOptions options;
  bool project = false;
  if (!ParseSolveArgs(args, in, out, reference, injected_after, project, options)) {
    std::fputs(kSolveUsage, stderr);
    return 2;
  }
  auto graph = ReadG2o(in);
  if (!graph.ok()) {
    std::fprintf(stderr, "cairn graph solve: %s\n", graph.status().message().c_str());
    return 1;
  }
  if (const size_t indefinite = graph->indefinite_edges(); indefinite > 0) {
    // What becomes of them; the geodesic objective without projection is the solver's to refuse.
    const bool sesync = options.objective == PoseGraphSolverOptions::Objective::kSeSync;
    if (project) {
      for (PoseGraphEdge& e : graph->edges()) {
        if (!e.definite) ProjectToPositiveDefinite(e);
      }
    }
    if (project || sesync) {
      std::fprintf(stderr, "cairn graph solve: %zu of %zu edges' information is not positive definite (first at %s): %s\n",
                   indefinite, graph->edges().size(), graph->first_indefinite().c_str(),
                   project ? "using the nearest positive-definite matrices"
                           : "the SE-Sync objective uses only their isotropic precisions");
    }
  }
  // Loop closures before the rest are lost with the edges the solve may drop.
  std::vector<bool> closure(graph->edges().size());
  for (size_t k = 0; k < closure.size(); ++k) closure[k] = IsLoopClosure(graph->edges()[k]);
  auto summary = SolvePoseGraph(*graph, options);
  if (!summary.ok()) {
    const bool hint = graph->indefinite_edges() > 0 && !project;
    std::fprintf(stderr, "cairn graph solve: %s%s\n", summary.status().message().c_str(),
                 hint ? " (--objective sesync, or --project-information for the nearest positive-definite matrices)"
                      : "");
    return 1;
  }
  std::string outlier_stats;
  if (injected_after >= 0) {
    // Recall: injected closures rejected; true closures kept.
    long long injected = 0, true_closures = 0, injected_rejected = 0, true_rejected = 0;
    std::vector<bool> rejected(closure.size(), false);
    for (size_t k : summary->rejected) rejected[k] = true;
    for (size_t k = 0; k < closure.size(); ++k) {
      if (!closure[k]) continue;
      const bool is_injected = static_cast<long long>(k) >= injected_after;
      (is_injected ? injected : true_closures) += 1;
      if (rejected[k]) (is_injected ? injected_rejected : true_rejected) += 1;
    }
    char buffer[256];
    std::snprintf(buffer, sizeof buffer,
                  ", \"injected\": %lld, \"injected_rejected\": %lld, \"true_closures\": %lld, \"true_kept\": %lld",
                  injected, injected_rejected, true_closures, true_closures - true_rejected);
    outlier_stats = buffer;
  }
  if (!out.empty()) {
    const Status s = WriteG2o(out, *graph);
    if (!s.ok()) {
      std::fprintf(stderr, "cairn graph solve: %s\n", s.message().c_str());
      return 1;
    }
  }
  double ate = -1.0;
  if (!reference.empty()) {
    auto ref = ReadG2o(reference);
    if (!ref.ok()) {
      std::fprintf(stderr, "cairn graph solve: %s\n", ref.status().message().c_str());
      return 1;
    }
    ate = AbsoluteTrajectoryError(*graph, *ref);
  }
  std::printf(
      "{\"input\": \"%s\", \"ate_vs_reference\": %.6g, \"vertices\": %zu, \"edges\": %zu, \"components\": %d, "
      "\"sesync_cost\": %.10g, \"geodesic_chi2\": %.10g, \"initial_sesync_cost\": %.10g, "
      "\"iterations\": %d, \"rejected_edges\": %d, \"init_seconds\": %.4f, \"solve_seconds\": %.4f, "
      "\"outlier_seconds\": %.4f, \"noise_scale\": %.6g, \"scale_seconds\": %.4f, \"wall_seconds\": %.4f%s}\n",
      in.c_str(), ate, graph->num_vertices(), graph->edges().size(), summary->components,
      summary->sesync_cost, summary->geodesic_chi2, summary->initial_sesync_cost, summary->iterations,
      summary->rejected_edges, summary->init_seconds, summary->solve_seconds, summary->outlier_seconds,
      summary->noise_scale, summary->scale_seconds, summary->init_seconds + summary->solve_seconds, outlier_stats.c_str());
  return 0;
}

}  // namespace cairn::tools

namespace cairn::tools {
namespace {

double Percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())))];
}

}  // namespace

constexpr const char* kReplayUsage =
    "usage: cairn graph replay IN.g2o|DIR [--loss none|cauchy:C] [--iterations N] [--reinitialize-cost C] [--inline]\n";

int RunGraphReplay(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kReplayUsage);
  std::string in;
  SlamGraphOptions options;
  options.cauchy_c = 0.0;
  bool background = true;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    if (a == "--loss" && i + 1 < args.args.size()) {
      const std::string v = args.args[++i];
      options.cauchy_c = v.rfind("cauchy:", 0) == 0 ? std::atof(v.c_str() + 7) : 0.0;
    } else if (a == "--reinitialize-cost" && i + 1 < args.args.size()) {
      options.reinitialize_cost = std::atof(args.args[++i]);
    } else if (a == "--iterations" && i + 1 < args.args.size()) {
      options.update_iterations = std::max(1, std::atoi(args.args[++i]));
    } else if (a == "--inline") {
      background = false;
    } else if (in.empty() && a.rfind("--", 0) != 0) {
      in = a;
    } else {
      std::fputs(kReplayUsage, stderr);
      return 2;
    }
  }
  auto graph = ReadG2o(in);
  if (!graph.ok()) {
    std::fprintf(stderr, "cairn graph replay: %s\n", graph.status().message().c_str());
    return 1;
  }
  PoseGraph& g = *graph;
  const auto start = std::chrono::steady_clock::now();
  GraphWorker worker;  // full solves off the online thread unless --inline
  auto replay = ReplayPoseGraph(g, options, background ? worker.Runner() : SlamGraph::BackgroundRunner{});
  if (!replay.ok()) {
    std::fprintf(stderr, "cairn graph replay: %s\n", replay.status().message().c_str());
    return 1;
  }
  const double total = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  const std::vector<double>& times = replay->step_seconds;
  double mean = 0.0;
  for (double t : times) mean += t;
  mean /= static_cast<double>(std::max<size_t>(1, times.size()));
  std::printf(
      "{\"input\": \"%s\", \"steps\": %zu, \"step_mean_ms\": %.3f, \"step_p99_ms\": %.3f, "
      "\"step_max_ms\": %.3f, \"background\": %s, \"full_solves\": %d, \"stale_full_solves\": %d, "
      "\"reinitializations\": %d, \"settle_ms\": %.3f, \"total_seconds\": %.3f, \"unconnected\": %zu, "
      "\"sesync_cost\": %.10g, \"geodesic_chi2\": %.10g}\n",
      in.c_str(), times.size(), 1e3 * mean, 1e3 * Percentile(times, 0.99),
      1e3 * (times.empty() ? 0.0 : *std::max_element(times.begin(), times.end())), background ? "true" : "false",
      replay->full_solves, replay->stale_full_solves, replay->reinitializations, 1e3 * replay->settle_seconds, total,
      replay->unconnected, SeSyncCost(g), GeodesicChi2(g));
  return 0;
}

}  // namespace cairn::tools

namespace cairn::tools {

// False loop closures for robustness tests. Generator (documented contract): with
// n = round(F * number of existing loop closures) (at least 1), each false closure joins two
// distinct vertices drawn uniformly, its measurement is a uniform random rotation (yaw only for
// planar graphs) and a translation uniform in [-s, s]^3 (z = 0 when planar), s = half the extent of
// the vertex estimates, and its information is that of a uniformly drawn existing loop closure (of
// an odometry edge when there is none). std::mt19937_64 seeded with N.
constexpr const char* kInjectUsage =
    "usage: cairn graph inject IN.g2o --fraction F --seed N --out OUT.g2o\n";

int RunGraphInject(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kInjectUsage);
  std::string in, out;
  double fraction = -1.0;
  uint64_t seed = 0;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool more = i + 1 < args.args.size();
    if (a == "--fraction" && more) {
      fraction = std::atof(args.args[++i]);
    } else if (a == "--seed" && more) {
      seed = std::strtoull(args.args[++i], nullptr, 10);
    } else if (a == "--out" && more) {
      out = args.args[++i];
    } else if (in.empty() && a.rfind("--", 0) != 0) {
      in = a;
    } else {
      in.clear();
      break;
    }
  }
  if (in.empty() || out.empty() || !(fraction >= 0.0 && fraction <= 10.0)) {
    std::fputs(kInjectUsage, stderr);
    return 2;
  }
  auto graph = ReadG2o(in);
  if (!graph.ok()) {
    std::fprintf(stderr, "cairn graph inject: %s\n", graph.status().message().c_str());
    return 1;
  }
  PoseGraph& g = *graph;
  if (!g.has_initial_estimate()) InitializeFromSpanningTree(g);
  std::vector<size_t> closures;
  for (size_t k = 0; k < g.edges().size(); ++k) {
    if (IsLoopClosure(g.edges()[k])) closures.push_back(k);
  }
  const bool planar = g.planar();
  Eigen::Vector3d lo = g.poses()[0].t, hi = lo;
  for (const auto& p : g.poses()) {
    lo = lo.cwiseMin(p.t);
    hi = hi.cwiseMax(p.t);
  }
  const double s = std::max(0.5 * (hi - lo).maxCoeff(), 1.0);
  const size_t n = std::max<size_t>(1, static_cast<size_t>(std::lround(fraction * static_cast<double>(closures.size()))));
  std::mt19937_64 rng(seed);
  std::uniform_int_distribution<size_t> vertex(0, g.num_vertices() - 1);
  std::uniform_int_distribution<size_t> template_edge(0, (closures.empty() ? g.edges().size() : closures.size()) - 1);
  std::uniform_real_distribution<double> uniform(-1.0, 1.0);
  std::normal_distribution<double> normal(0.0, 1.0);
  for (size_t k = 0; k < n && g.num_vertices() > 1; ++k) {
    size_t i = vertex(rng), j = vertex(rng);
    while (j == i) j = vertex(rng);
    PoseGraphEdge e = g.edges()[closures.empty() ? template_edge(rng) : closures[template_edge(rng)]];
    e.from = g.ids()[i];
    e.to = g.ids()[j];
    // Last component first (estimation/math/ordered_draws.h).
    const double z = planar ? 0.0 : s * uniform(rng);
    const double y = s * uniform(rng);
    const double x = s * uniform(rng);
    e.T_from_to.t = Eigen::Vector3d(x, y, z);
    if (planar) {
      e.T_from_to.q = Eigen::Quaterniond(Eigen::AngleAxisd(M_PI * uniform(rng), Eigen::Vector3d::UnitZ()));
    } else {
      e.T_from_to.q = DrawQuaternion(normal, rng).normalized();
    }
    g.AddEdge(e);
  }
  const Status st = WriteG2o(out, g);
  if (!st.ok()) {
    std::fprintf(stderr, "cairn graph inject: %s\n", st.message().c_str());
    return 1;
  }
  std::printf("{\"input\": \"%s\", \"output\": \"%s\", \"loop_closures\": %zu, \"injected\": %zu, \"seed\": %llu}\n",
              in.c_str(), out.c_str(), closures.size(), n, static_cast<unsigned long long>(seed));
  return 0;
}

}  // namespace cairn::tools

namespace cairn::tools {

// Thesis-sized online benchmark (thesis 8.3: < 180 nodes and 250 factors per experiment): R robots
// with `submaps` submap origins in total, chained by frame switches, plus random noisy submap
// matches until `factors` factors; fed interleaved as they would arrive, one Update() per factor.
// Then the marginal covariances of all submap origins. Repeated with different seeds; medians.
constexpr const char* kBenchGraphUsage =
    "usage: cairn bench graph [--robots R] [--submaps S] [--factors F] [--repeats N] [--inline]\n";

int RunBenchGraph(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchGraphUsage);
  int robots = 3, submaps = 200, factors = 300, repeats = 5;
  bool background = true;
  for (size_t i = 0; i < args.args.size(); i += 2) {
    const std::string a = args.args[i];
    if (a == "--inline") {
      background = false;
      --i;
      continue;
    }
    const int v = i + 1 < args.args.size() ? std::atoi(args.args[i + 1]) : 0;
    if (a == "--robots") robots = std::clamp(v, 1, 20);
    else if (a == "--submaps") submaps = std::max(v, robots);
    else if (a == "--factors") factors = std::max(v, submaps);
    else if (a == "--repeats") repeats = std::max(v, 1);
    else {
      std::fputs(kBenchGraphUsage, stderr);
      return 2;
    }
  }
  std::vector<double> means, p99s, maxima, cpu_means, cpu_maxima, covariance_times, chi2s, batch_chi2s, window_sizes,
      full_solve_counts;
  // The online thread's own CPU time next to wall time: on a loaded machine (or with the full
  // solve sharing the cores) wall time includes waiting to be scheduled.
  for (int rep = 0; rep < repeats; ++rep) {
    std::mt19937 rng(static_cast<unsigned>(rep + 1));
    std::normal_distribution<double> n(0.0, 1.0);
    std::uniform_int_distribution<int> pick(0, submaps - 1);
    auto noisy = [&](const Pose3& p) {
      const Eigen::Vector3d dt = 0.02 * DrawVector3(n, rng);
      return p * Pose3{dt, so3::ExpQuaternion(0.005 * DrawVector3(n, rng))};
    };
    // True origins: each robot drives a wavy line from its own start.
    std::vector<Pose3> truth(static_cast<size_t>(submaps));
    std::vector<uint64_t> keys(static_cast<size_t>(submaps));
    for (int s = 0; s < submaps; ++s) {
      const int r = s % robots, k = s / robots;
      const Pose3 start{Eigen::Vector3d(0, 5.0 * r, 0), Eigen::Quaterniond::Identity()};
      truth[static_cast<size_t>(s)] = start * Pose3{Eigen::Vector3d(2.0 * k, 3.0 * std::sin(0.2 * k), 0.1 * std::sin(0.1 * k)),
                                                    so3::ExpQuaternion(Eigen::Vector3d(0, 0, 0.6 * std::cos(0.2 * k)))};
      keys[static_cast<size_t>(s)] = VariableKey(VariableKind::kSubmap, static_cast<char>('a' + r), static_cast<uint64_t>(k));
    }
    Matrix6d info = Matrix6d::Identity();
    info.topLeftCorner<3, 3>() *= 1.0 / (0.02 * 0.02);
    info.bottomRightCorner<3, 3>() *= 1.0 / (0.005 * 0.005);
    GraphWorker worker;  // declared before the graph: outlives its runner
    SlamGraph g;
    if (background) g.SetBackgroundRunner(worker.Runner());
    std::vector<double> times, cpu_times;
    double window_sum = 0.0;
    int windows = 0;
    auto feed = [&](const SlamFactor& f) {
      const auto t0 = std::chrono::steady_clock::now();
      const double c0 = ThreadCpuMs();
      if (!g.AddFactor(f).ok()) std::abort();
      const SlamUpdateStats st = g.Update();
      cpu_times.push_back(1e-3 * (ThreadCpuMs() - c0));
      times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      if (st.solved && !st.full_solve_merged) {
        window_sum += st.window_variables;
        ++windows;
      }
    };
    SlamFactor prior;
    prior.kind = FactorKind::kPrior;
    prior.a = keys[0];
    prior.z = truth[0];
    prior.information = info;
    feed(prior);
    int count = 1;
    for (int s = robots; s < submaps; ++s) {
      SlamFactor w;
      w.kind = FactorKind::kFrameSwitch;
      w.a = keys[static_cast<size_t>(s - robots)];
      w.b = keys[static_cast<size_t>(s)];
      w.z = noisy(truth[static_cast<size_t>(s - robots)].Inverse() * truth[static_cast<size_t>(s)]);
      w.information = info;
      feed(w);
      ++count;
      // Matches to earlier submaps (any robot) at the rate that reaches `factors` in the end.
      while (count < 1 + (factors - 1) * (s - robots + 1) / (submaps - robots)) {
        const int other = pick(rng) % (s + 1);
        if (other == s) continue;
        SlamFactor c;
        c.kind = FactorKind::kMatch;
        c.a = keys[static_cast<size_t>(other)];
        c.b = keys[static_cast<size_t>(s)];
        c.z = noisy(truth[static_cast<size_t>(other)].Inverse() * truth[static_cast<size_t>(s)]);
        c.information = info;
        feed(c);
        ++count;
      }
    }
    double mean = 0.0;
    for (double t : times) mean += t;
    means.push_back(mean / static_cast<double>(times.size()));
    p99s.push_back(Percentile(times, 0.99));
    double cpu = 0.0;
    for (double t : cpu_times) cpu += t;
    cpu_means.push_back(cpu / static_cast<double>(cpu_times.size()));
    cpu_maxima.push_back(*std::max_element(cpu_times.begin(), cpu_times.end()));
    maxima.push_back(*std::max_element(times.begin(), times.end()));
    window_sizes.push_back(windows > 0 ? window_sum / windows : 0.0);
    // The online estimate once the last full solve is merged, as a moment later on the robot.
    g.Settle();
    full_solve_counts.push_back(g.full_solves());
    const auto t0 = std::chrono::steady_clock::now();
    auto cov = g.Covariances(keys);
    covariance_times.push_back(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    if (!cov.ok()) {
      std::fprintf(stderr, "cairn bench graph: %s\n", cov.status().message().c_str());
      return 1;
    }
    chi2s.push_back(g.Chi2());
    g.SolveFull();
    batch_chi2s.push_back(g.Chi2());
    if (rep == 0) std::fprintf(stderr, "factors %zu, variables %zu, unconnected %zu\n", g.num_factors(), g.num_variables(), g.Unconnected().size());
  }
  std::printf("{\"robots\": %d, \"submaps\": %d, \"factors\": %d, \"repeats\": %d, \"background\": %s, "
              "\"update_mean_ms\": %.3f, \"update_p99_ms\": %.3f, \"update_max_ms\": %.3f, "
              "\"update_cpu_mean_ms\": %.3f, \"update_cpu_max_ms\": %.3f, "
              "\"window_variables_mean\": %.1f, \"full_solves\": %.0f, \"covariances_all_origins_ms\": %.3f, "
              "\"online_chi2\": %.6g, \"batch_chi2\": %.6g}\n",
              robots, submaps, factors, repeats, background ? "true" : "false", 1e3 * Percentile(means, 0.5),
              1e3 * Percentile(p99s, 0.5), 1e3 * Percentile(maxima, 0.5), 1e3 * Percentile(cpu_means, 0.5),
              1e3 * Percentile(cpu_maxima, 0.5), Percentile(window_sizes, 0.5),
              Percentile(full_solve_counts, 0.5), 1e3 * Percentile(covariance_times, 0.5), Percentile(chi2s, 0.5),
              Percentile(batch_chi2s, 0.5));
  return 0;
}

}  // namespace cairn::tools
