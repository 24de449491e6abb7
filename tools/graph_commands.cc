// cairn graph solve | replay | inject: pose-graph back-end on standard g2o files.

#include <cstdio>
#include <cstdlib>
#include <string>

#include "estimation/g2o_io.h"
#include "estimation/pose_graph_solver.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr const char* kSolveUsage =
    "usage: cairn graph solve IN.g2o|DIR [--out OUT.g2o] [--objective geodesic|sesync]\n"
    "                         [--init chordal|odometry|file] [--loss none|cauchy:C]\n"
    "                         [--outliers none|gnc] [--threads N] [--verbose]\n";

bool ParseSolveArgs(const CommandArgs& args, std::string& in, std::string& out,
                    PoseGraphSolverOptions& o) {
  using O = PoseGraphSolverOptions;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    const std::string v = has_value ? args.args[i + 1] : "";
    if (a == "--verbose") {
      o.verbose = true;
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
    } else if (a == "--outliers" && (v == "none" || v == "gnc")) {
      o.outliers = v == "gnc" ? O::Outliers::kGnc : O::Outliers::kNone;
    } else if (a == "--threads") {
      o.threads = std::atoi(v.c_str());
      if (o.threads < 1) return false;
    } else {
      return false;
    }
  }
  return !in.empty();
}

}  // namespace

int RunGraphSolve(const CommandArgs& args) {
  std::string in, out;
  PoseGraphSolverOptions options;
  if (!ParseSolveArgs(args, in, out, options)) {
    std::fputs(kSolveUsage, stderr);
    return 2;
  }
  auto graph = ReadG2o(in);
  if (!graph.ok()) {
    std::fprintf(stderr, "cairn graph solve: %s\n", graph.status().message().c_str());
    return 1;
  }
  auto summary = SolvePoseGraph(*graph, options);
  if (!summary.ok()) {
    std::fprintf(stderr, "cairn graph solve: %s\n", summary.status().message().c_str());
    return 1;
  }
  if (!out.empty()) {
    const Status s = WriteG2o(out, *graph);
    if (!s.ok()) {
      std::fprintf(stderr, "cairn graph solve: %s\n", s.message().c_str());
      return 1;
    }
  }
  std::printf(
      "{\"input\": \"%s\", \"vertices\": %zu, \"edges\": %zu, \"components\": %d, "
      "\"sesync_cost\": %.10g, \"geodesic_chi2\": %.10g, \"initial_sesync_cost\": %.10g, "
      "\"iterations\": %d, \"rejected_edges\": %d, \"init_seconds\": %.4f, \"solve_seconds\": %.4f, "
      "\"wall_seconds\": %.4f}\n",
      in.c_str(), graph->num_vertices(), graph->edges().size(), summary->components,
      summary->sesync_cost, summary->geodesic_chi2, summary->initial_sesync_cost, summary->iterations,
      summary->rejected_edges, summary->init_seconds, summary->solve_seconds,
      summary->init_seconds + summary->solve_seconds);
  return 0;
}

}  // namespace cairn::tools
