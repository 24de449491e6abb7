#include "estimation/graph/graph_batch_job.h"

#include <algorithm>
#include <chrono>
#include <set>

#include <ceres/ceres.h>

#include "estimation/graph/chordal_initializer.h"
#include "estimation/graph/line_factors.h"
#include "estimation/graph/plane_factors.h"
#include "estimation/graph/pose_factors.h"

namespace cairn {

GraphSolveResult SolveGraphProblem(ceres::Problem& problem, int iterations, double seconds,
                                   double function_tolerance) {
  GraphSolveResult result;
  if (problem.NumResidualBlocks() == 0) {
    result.converged = true;
    return result;
  }
  ceres::Solver::Options o;
  // Sparse even for small windows: this Ceres' dense normal equations (J^T J of a dense J) cost
  // 2.5x CHOLMOD's on windows of 15 variables.
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.max_num_iterations = iterations;
  o.max_solver_time_in_seconds = seconds;
  o.function_tolerance = function_tolerance;
  o.gradient_tolerance = 1e-12;
  o.parameter_tolerance = 1e-10;
  o.num_threads = 1;
  o.logging_type = ceres::SILENT;
  ceres::Solver::Summary summary;
  ceres::Solve(o, &problem, &summary);
  result.iterations = static_cast<int>(summary.iterations.size()) - 1;
  result.cost = summary.final_cost;
  result.converged = summary.termination_type == ceres::CONVERGENCE;
  return result;
}

Status InitializeSnapshotChordal(GraphSnapshot& s) {
  auto index = [&](uint64_t key) {
    return static_cast<size_t>(std::lower_bound(s.keys.begin(), s.keys.end(), key) - s.keys.begin());
  };
  PoseGraph g;
  // Anchors first: InitializeChordal keeps the first vertex of each component.
  for (const auto& f : s.factors) {
    if (f.kind == FactorKind::kPrior || f.kind == FactorKind::kAbsolutePose) g.SetVertex(f.a, s.poses[index(f.a)]);
  }
  for (size_t i = 0; i < s.keys.size(); ++i) {
    if (s.constant[i]) g.SetVertex(s.keys[i], s.poses[i]);
  }
  for (size_t i = 0; i < s.keys.size(); ++i) {
    if (!g.HasVertex(s.keys[i])) g.SetVertex(s.keys[i], s.poses[i]);
  }
  for (const auto& f : s.factors) {
    if (IsPoseEdge(f.kind)) g.AddEdge(EdgeOfFactor(f));
  }
  CAIRN_RETURN_IF_ERROR(InitializeChordal(g));
  for (size_t i = 0; i < g.num_vertices(); ++i) s.poses[index(g.ids()[i])] = g.poses()[i];
  // Plane and line landmarks are no vertices of the pose graph: each goes back onto its plane or
  // line as the submap that created it (its first observation) now sees it.
  std::set<uint64_t> placed;
  for (const auto& f : s.factors) {
    if (IsStructureObservation(f.kind) && placed.insert(f.b).second) {
      s.poses[index(f.b)] = s.poses[index(f.a)] * f.z;
    }
  }
  return Status::Ok();
}

GraphBatchJob::GraphBatchJob(GraphSnapshot snapshot, bool chordal, double cauchy_c, int64_t iterations,
                             uint64_t version)
    : snapshot_(std::move(snapshot)), chordal_(chordal), cauchy_c_(cauchy_c), iterations_(iterations),
      version_(version) {}

void GraphBatchJob::Run() {
  const auto start = std::chrono::steady_clock::now();
  GraphSnapshot& s = snapshot_;
  if (chordal_) reinitialized_ = InitializeSnapshotChordal(s).ok();
  const size_t n = s.keys.size();
  std::vector<double> blocks(7 * n);
  for (size_t i = 0; i < n; ++i) PoseToBlock(s.poses[i], &blocks[7 * i]);
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem problem(po);
  const auto manifold = MakePoseManifold();
  const auto plane_manifold = MakePlaneLandmarkManifold();
  const auto line_manifold = MakeLineLandmarkManifold();
  ceres::CauchyLoss cauchy(cauchy_c_ > 0.0 ? cauchy_c_ : 1.0);
  auto block = [&](uint64_t key) {
    return &blocks[7 * static_cast<size_t>(std::lower_bound(s.keys.begin(), s.keys.end(), key) - s.keys.begin())];
  };
  for (const auto& f : s.factors) {
    ceres::LossFunction* loss = cauchy_c_ > 0.0 && IsRobustFactor(f.kind) ? &cauchy : nullptr;
    if (IsUnary(f.kind)) {
      problem.AddResidualBlock(MakeFactorCostFunction(f), loss, block(f.a));
    } else {
      problem.AddResidualBlock(MakeFactorCostFunction(f), loss, block(f.a), block(f.b));
    }
  }
  for (size_t i = 0; i < n; ++i) {
    double* b = &blocks[7 * i];
    if (!problem.HasParameterBlock(b)) continue;
    const int tangent = TangentSizeOf(s.keys[i]);
    problem.SetManifold(b, tangent == 3   ? plane_manifold.get()
                           : tangent == 4 ? line_manifold.get()
                                          : manifold.get());
    if (s.constant[i]) problem.SetParameterBlockConstant(b);
  }
  stats_ = SolveGraphProblem(problem, static_cast<int>(iterations_), 1e9);
  for (size_t i = 0; i < n; ++i) s.poses[i] = BlockToPose(&blocks[7 * i]);
  seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  done_.store(true, std::memory_order_release);
  done_.notify_all();
}

}  // namespace cairn
