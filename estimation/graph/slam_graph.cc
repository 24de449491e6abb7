#include "estimation/graph/slam_graph.h"

#include <algorithm>
#include <chrono>
#include <cmath>

#include <ceres/ceres.h>

#include "estimation/graph/graph_batch_job.h"
#include "estimation/graph/line_factors.h"
#include "estimation/graph/marginal_covariance.h"
#include "estimation/graph/plane_factors.h"
#include "estimation/graph/pose_factors.h"
#include "estimation/math/so3.h"

namespace cairn {

namespace {

Status CheckKinds(const SlamFactor& f, char own_robot) {
  using K = VariableKind;
  const K ka = KindOfKey(f.a), kb = KindOfKey(f.b);
  const bool same_robot = RobotOfVariable(f.a) == RobotOfVariable(f.b);
  auto is = [](K k) {
    return k == K::kRobotPose || k == K::kSubmap || k == K::kLandmark || k == K::kDatum || k == K::kPlane ||
           k == K::kLine;
  };
  if (!is(ka) || (!IsUnary(f.kind) && !is(kb))) return InvalidArgumentError("factor on a malformed variable key");
  if (!IsUnary(f.kind) && f.a == f.b) return InvalidArgumentError("binary factor on one variable");
  bool ok = true;
  switch (f.kind) {
    case FactorKind::kPrior: ok = ka == K::kSubmap && RobotOfVariable(f.a) == own_robot; break;
    case FactorKind::kFrameSwitch: ok = ka == K::kSubmap && kb == K::kSubmap && same_robot; break;
    case FactorKind::kFilterEstimate: ok = ka == K::kSubmap && kb == K::kRobotPose && same_robot; break;
    case FactorKind::kOdometry: ok = ka == K::kRobotPose && kb == K::kRobotPose && same_robot; break;
    case FactorKind::kDetection: ok = ka == K::kRobotPose && kb == K::kRobotPose && !same_robot; break;
    case FactorKind::kLandmark: ok = ka == K::kRobotPose && kb == K::kLandmark; break;
    case FactorKind::kMatch:  // submap origins are robot poses in the sequential topology
      ok = (ka == K::kSubmap || ka == K::kRobotPose) && (kb == K::kSubmap || kb == K::kRobotPose);
      break;
    case FactorKind::kAbsolutePose:
    case FactorKind::kAbsolutePosition: ok = true; break;
    case FactorKind::kGnssPosition:
      ok = ka == K::kDatum && kb == K::kRobotPose;
      break;
    case FactorKind::kPlaneObservation:
      ok = ka == K::kSubmap && kb == K::kPlane;
      break;
    case FactorKind::kLineObservation:
      ok = ka == K::kSubmap && kb == K::kLine;
      break;
  }
  if (!ok) return InvalidArgumentError("factor kind does not fit its variables");
  if (f.kind == FactorKind::kPlaneObservation) {
    if (!f.plane.allFinite() || std::abs(f.plane.head<3>().norm() - 1.0) > 1e-6 || !f.z.t.allFinite() ||
        !f.z.q.coeffs().allFinite()) {
      return InvalidArgumentError("plane observation with a non-finite plane or a normal not of unit length");
    }
    if (!f.plane_information.allFinite() || f.plane_information.llt().info() != Eigen::Success) {
      return InvalidArgumentError("plane information is not positive definite");
    }
  } else if (f.kind == FactorKind::kLineObservation) {
    if (!f.line_point.allFinite() || !f.line_direction.allFinite() ||
        std::abs(f.line_direction.norm() - 1.0) > 1e-6 || !f.z.t.allFinite() || !f.z.q.coeffs().allFinite()) {
      return InvalidArgumentError(
          "line observation with a non-finite line or a direction not of unit length");
    }
    if (!f.line_information.allFinite() || f.line_information.llt().info() != Eigen::Success) {
      return InvalidArgumentError("line information is not positive definite");
    }
  } else if (IsPositionFactor(f.kind)) {
    if (!f.position.allFinite() || !f.antenna.allFinite()) return InvalidArgumentError("non-finite position");
    if (f.position_information.llt().info() != Eigen::Success) {
      return InvalidArgumentError("position information is not positive definite");
    }
  } else if (f.information.llt().info() != Eigen::Success) {
    return InvalidArgumentError("information is not positive definite");
  }
  return Status::Ok();
}

SlamUpdateStats StatsOf(const GraphSolveResult& r, size_t variables, std::chrono::steady_clock::time_point start) {
  SlamUpdateStats stats;
  stats.solved = true;
  stats.iterations = r.iterations;
  stats.cost = r.cost;
  stats.window_variables = static_cast<int>(variables);
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

}  // namespace

SlamGraph::SlamGraph(const SlamGraphOptions& options)
    : options_(options),
      manifold_(MakePoseManifold()),
      plane_manifold_(MakePlaneLandmarkManifold()),
      line_manifold_(MakeLineLandmarkManifold()) {
  ceres::Problem::Options po;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  // Removing nothing, but covariance queries and warm starts look blocks up often.
  po.enable_fast_removal = false;
  problem_ = std::make_unique<ceres::Problem>(po);
  if (options_.cauchy_c > 0.0) cauchy_ = std::make_unique<ceres::CauchyLoss>(options_.cauchy_c);
}

SlamGraph::~SlamGraph() = default;

Status SlamGraph::AddFactor(const SlamFactor& f) {
  CAIRN_RETURN_IF_ERROR(CheckKinds(f, options_.own_robot));
  if (f.kind == FactorKind::kGnssPosition) {
    // A position alone cannot place a pose or a datum, nor join a floating component rigidly.
    if (!HasVariable(f.a) || !HasVariable(f.b))
      return InvalidArgumentError("GNSS fix on an unknown datum or pose");
    if (variables_.at(f.a).component != variables_.at(f.b).component) {
      return InvalidArgumentError("GNSS fix on a pose not tied to the datum");
    }
  }
  if (IsStructureObservation(f.kind)) {
    // A plane fixes 3 of a pose's 6 degrees of freedom, a line 4: neither can place a submap nor
    // join components rigidly.
    const char* what = f.kind == FactorKind::kPlaneObservation ? "plane" : "line";
    if (!HasVariable(f.a))
      return InvalidArgumentError(std::string(what) + " observation by an unknown submap");
    if (HasVariable(f.b) && variables_.at(f.a).component != variables_.at(f.b).component) {
      return InvalidArgumentError(std::string(what) + " observation across unconnected components");
    }
  }
  ++num_added_factors_;
  if (f.kind == FactorKind::kAbsolutePosition && !HasVariable(f.a)) {
    pending_.push_back(f);  // no orientation to start it from: wait for the variable
    return Status::Ok();
  }
  Insert(f);
  // A new variable may release waiting position fixes.
  for (size_t k = 0; k < pending_.size();) {
    if (HasVariable(pending_[k].a)) {
      const SlamFactor p = pending_[k];
      pending_.erase(pending_.begin() + static_cast<long>(k));
      Insert(p);
    } else {
      ++k;
    }
  }
  return Status::Ok();
}

SlamGraph::Variable& SlamGraph::CreateVariable(uint64_t key, const Pose3& initial, int component,
                                               uint64_t parent) {
  Variable& v = variables_[key];
  v.block.reset(new double[7]);
  PoseToBlock(initial, v.block.get());
  v.component = component;
  v.parent = parent;
  creation_order_.push_back(key);
  problem_->AddParameterBlock(v.block.get(), 7, ManifoldOf(key));
  auto& members = components_[component];
  if (members.empty() && component != own_component_) {
    v.gauge = true;  // first variable of a floating component holds its gauge
    problem_->SetParameterBlockConstant(v.block.get());
  }
  members.insert(key);
  if (KindOfKey(key) == VariableKind::kSubmap) {
    auto [it, inserted] = latest_submap_.emplace(RobotOfVariable(key), key);
    if (!inserted && IndexOfVariable(key) > IndexOfVariable(it->second)) it->second = key;
  }
  return v;
}

void SlamGraph::JoinComponents(int keep, int drop, const Pose3& correction) {
  ++structure_version_;
  for (uint64_t key : components_[drop]) {
    Variable& v = variables_.at(key);
    PoseToBlock(correction * BlockToPose(v.block.get()), v.block.get());
    v.component = keep;
    if (v.gauge) {  // the kept component's gauge (or the prior) now fixes the dropped one
      v.gauge = false;
      problem_->SetParameterBlockVariable(v.block.get());
    }
    components_[keep].insert(key);
  }
  components_.erase(drop);
}

void SlamGraph::AnchorToWorld(uint64_t key, const Pose3& pose) {
  if (own_component_ < 0) {
    own_component_ = next_component_++;
    components_[own_component_];
  }
  auto it = variables_.find(key);
  if (it == variables_.end()) {
    CreateVariable(key, pose, own_component_, key);
  } else if (it->second.component != own_component_) {
    const Pose3 correction = pose * BlockToPose(it->second.block.get()).Inverse();
    JoinComponents(own_component_, it->second.component, correction);
  }
}

void SlamGraph::Insert(const SlamFactor& f) {
  ceres::LossFunction* loss = IsRobustFactor(f.kind) ? cauchy_.get() : nullptr;
  ceres::CostFunction* cost = MakeFactorCostFunction(f);
  ceres::ResidualBlockId id = nullptr;
  if (f.kind == FactorKind::kPrior || f.kind == FactorKind::kAbsolutePose) {
    AnchorToWorld(f.a, f.z);
    id = problem_->AddResidualBlock(cost, loss, variables_.at(f.a).block.get());
  } else if (f.kind == FactorKind::kAbsolutePosition) {
    // Translates a floating component onto the fix but keeps it floating: one position does not
    // fix its orientation.
    Variable& v = variables_.at(f.a);
    if (v.component != own_component_) {
      ++structure_version_;
      const Pose3 here = BlockToPose(v.block.get());
      const Pose3 shift{f.position - here.t, Eigen::Quaterniond::Identity()};
      for (uint64_t key : components_[v.component]) {
        double* b = variables_.at(key).block.get();
        PoseToBlock(shift * BlockToPose(b), b);
      }
    }
    id = problem_->AddResidualBlock(cost, loss, v.block.get());
  } else {
    const bool has_a = HasVariable(f.a), has_b = HasVariable(f.b);
    if (!has_a && !has_b) {
      const int c = next_component_++;
      CreateVariable(f.a, Pose3(), c, f.a);
      CreateVariable(f.b, f.z, c, f.a);
    } else if (!has_b) {
      const Variable& a = variables_.at(f.a);
      CreateVariable(f.b, BlockToPose(a.block.get()) * f.z, a.component, f.a);
    } else if (!has_a) {
      const Variable& b = variables_.at(f.b);
      CreateVariable(f.a, BlockToPose(b.block.get()) * f.z.Inverse(), b.component, f.b);
    } else {
      const Variable& a = variables_.at(f.a);
      const Variable& b = variables_.at(f.b);
      if (a.component != b.component) {
        const Pose3 Ta = BlockToPose(a.block.get()), Tb = BlockToPose(b.block.get());
        if (a.component == own_component_) {
          JoinComponents(a.component, b.component, (Ta * f.z) * Tb.Inverse());
        } else {
          JoinComponents(b.component, a.component, (Tb * f.z.Inverse()) * Ta.Inverse());
        }
      }
    }
    id = problem_->AddResidualBlock(cost, loss, variables_.at(f.a).block.get(), variables_.at(f.b).block.get());
  }
  double c = 0.0;
  problem_->EvaluateResidualBlock(id, true, &c, nullptr, nullptr);
  new_cost_ += c;
  const auto index = static_cast<uint32_t>(factors_.size());
  variables_.at(f.a).factors.push_back(index);
  if (!IsUnary(f.kind)) variables_.at(f.b).factors.push_back(index);
  factors_.push_back(f);
  residual_ids_.push_back(id);
}

SlamUpdateStats SlamGraph::Solve(int iterations, double seconds) {
  SlamUpdateStats stats;
  if (problem_->NumResidualBlocks() == 0) return stats;
  const auto start = std::chrono::steady_clock::now();
  return StatsOf(SolveGraphProblem(*problem_, iterations, seconds), variables_.size(), start);
}

std::vector<uint64_t> SlamGraph::WindowAround(const std::vector<uint64_t>& seeds) const {
  // Breadth first from the seeds, so the cap keeps the nearest variables.
  const auto cap = static_cast<size_t>(options_.window_variables);
  std::vector<uint64_t> window;
  std::set<uint64_t> seen;
  for (uint64_t key : seeds) {
    if (window.size() < cap && HasVariable(key) && seen.insert(key).second) window.push_back(key);
  }
  size_t level_begin = 0;
  for (int64_t hop = 0; hop < options_.window_hops && window.size() < cap; ++hop) {
    const size_t level_end = window.size();
    for (size_t i = level_begin; i < level_end && window.size() < cap; ++i) {
      for (uint32_t k : variables_.at(window[i]).factors) {
        const SlamFactor& f = factors_[k];
        if (IsUnary(f.kind)) continue;
        const uint64_t other = f.a == window[i] ? f.b : f.a;
        if (seen.insert(other).second) {
          window.push_back(other);
          if (window.size() >= cap) break;
        }
      }
    }
    level_begin = level_end;
  }
  return window;
}

SlamUpdateStats SlamGraph::SolveWindow(const std::vector<uint64_t>& seeds) {
  const auto start = std::chrono::steady_clock::now();
  std::vector<uint64_t> window = WindowAround(seeds);
  std::sort(window.begin(), window.end());
  auto in_window = [&](uint64_t key) { return std::binary_search(window.begin(), window.end(), key); };
  // A problem of the window's factors only: the rest of the graph never enters the solver, so the
  // update's cost does not grow with the graph. The factors' residuals are shared, not copied.
  ceres::Problem::Options po;
  po.cost_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.loss_function_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  po.manifold_ownership = ceres::DO_NOT_TAKE_OWNERSHIP;
  ceres::Problem local(po);
  std::vector<uint32_t> used;
  for (uint64_t key : window) {
    for (uint32_t k : variables_.at(key).factors) used.push_back(k);
  }
  std::sort(used.begin(), used.end());
  used.erase(std::unique(used.begin(), used.end()), used.end());
  std::set<uint64_t> blocks_of_used;
  for (uint32_t k : used) {
    const SlamFactor& f = factors_[k];
    const ceres::ResidualBlockId id = residual_ids_[k];
    ceres::CostFunction* cost = const_cast<ceres::CostFunction*>(problem_->GetCostFunctionForResidualBlock(id));
    ceres::LossFunction* loss = const_cast<ceres::LossFunction*>(problem_->GetLossFunctionForResidualBlock(id));
    blocks_of_used.insert(f.a);
    if (IsUnary(f.kind)) {
      local.AddResidualBlock(cost, loss, variables_.at(f.a).block.get());
    } else {
      blocks_of_used.insert(f.b);
      local.AddResidualBlock(cost, loss, variables_.at(f.a).block.get(), variables_.at(f.b).block.get());
    }
  }
  for (uint64_t key : blocks_of_used) {
    const Variable& v = variables_.at(key);
    local.SetManifold(v.block.get(), ManifoldOf(key));
    if (v.gauge || !in_window(key)) local.SetParameterBlockConstant(v.block.get());
  }
  // A window only has to be good until the next full solve: a looser tolerance than the full
  // solve's saves the last iterations.
  const GraphSolveResult r =
      SolveGraphProblem(local, static_cast<int>(options_.update_iterations), options_.update_seconds,
                        options_.window_tolerance);
  if (!r.converged) unconverged_ = seeds;
  return StatsOf(r, window.size(), start);
}

GraphSnapshot SlamGraph::Snapshot() const {
  GraphSnapshot s;
  s.factors = factors_;
  s.keys.reserve(variables_.size());
  s.poses.reserve(variables_.size());
  s.constant.reserve(variables_.size());
  for (const auto& [key, v] : variables_) {
    s.keys.push_back(key);
    s.poses.push_back(BlockToPose(v.block.get()));
    s.constant.push_back(v.gauge ? 1 : 0);
  }
  return s;
}

void SlamGraph::StartFullSolve(bool chordal) {
  job_ = std::make_shared<GraphBatchJob>(Snapshot(), chordal, options_.cauchy_c, options_.full_iterations,
                                         structure_version_);
  job_factors_ = factors_.size();
  job_variables_ = creation_order_.size();
  full_solve_wanted_ = chordal_wanted_ = false;
  runner_([job = job_] { job->Run(); });
}

bool SlamGraph::MergeFullSolve() {
  const std::shared_ptr<GraphBatchJob> job = std::move(job_);
  if (job->version() != structure_version_) {
    ++stale_full_solves_;
    return false;
  }
  ++full_solves_;
  const GraphSnapshot& r = job->result();
  // Left corrections: the solved pose of each snapshot variable times its current pose's inverse
  // (which may include window updates made meanwhile, superseded by the full solve).
  std::map<uint64_t, Pose3> correction;
  for (size_t i = 0; i < r.keys.size(); ++i) {
    Variable& v = variables_.at(r.keys[i]);
    correction[r.keys[i]] = r.poses[i] * BlockToPose(v.block.get()).Inverse();
    PoseToBlock(r.poses[i], v.block.get());
  }
  // Variables created meanwhile follow the variable they were placed from (creation order, so a
  // parent's correction is known before its children's).
  for (size_t k = job_variables_; k < creation_order_.size(); ++k) {
    const uint64_t key = creation_order_[k];
    Variable& v = variables_.at(key);
    auto it = correction.find(v.parent);
    if (it == correction.end()) continue;  // a new anchor or floating component: not in the solve
    const Pose3 c = it->second;
    PoseToBlock(c * BlockToPose(v.block.get()), v.block.get());
    correction[key] = c;
  }
  return true;
}

bool SlamGraph::MergeRunningJob() {
  job_->Wait();
  const size_t first_new = job_factors_;
  if (!MergeFullSolve()) {
    full_solve_wanted_ = true;
    return false;
  }
  for (size_t k = factors_.size(); k-- > first_new;) {  // newest first, as the window takes them
    unconverged_.push_back(factors_[k].a);
    if (!IsUnary(factors_[k].kind)) unconverged_.push_back(factors_[k].b);
  }
  return true;
}

void SlamGraph::WaitForBackground() {
  if (job_) MergeRunningJob();
}

int SlamGraph::Settle(int max_rounds) {
  int reinitializations = 0;
  for (int round = 0; round < max_rounds && job_; ++round) {
    WaitForBackground();
    reinitializations += Update().reinitialized ? 1 : 0;
  }
  return reinitializations;
}

SlamUpdateStats SlamGraph::Update() {
  const auto start = std::chrono::steady_clock::now();
  SlamUpdateStats merged;
  if (job_ && job_->Done()) {
    const bool reinitialized = job_->reinitialized();
    merged.full_solve_merged = MergeRunningJob();
    merged.reinitialized = merged.full_solve_merged && reinitialized;
  }
  // Newest factors first: when more arrived than one window holds, the older ones wait for the
  // full solve that their cost has asked for.
  std::vector<uint64_t> seeds;
  if (new_cost_ > options_.update_min_cost) {
    for (size_t k = factors_.size(); k-- > solved_factors_;) {
      seeds.push_back(factors_[k].a);
      if (!IsUnary(factors_[k].kind)) seeds.push_back(factors_[k].b);
    }
    if (new_cost_ > options_.full_solve_cost) full_solve_wanted_ = true;
    if (options_.reinitialize_cost > 0.0 && new_cost_ > options_.reinitialize_cost) chordal_wanted_ = true;
  }
  seeds.insert(seeds.end(), unconverged_.begin(), unconverged_.end());
  unconverged_.clear();
  new_cost_ = 0.0;
  solved_factors_ = factors_.size();
  SlamUpdateStats stats;
  if (!runner_ && full_solve_wanted_) {
    // Inline: the full solve covers the window.
    const bool reinitialized = chordal_wanted_ && ReinitializeChordal().ok();
    full_solve_wanted_ = chordal_wanted_ = false;
    stats = SolveFull();
    stats.reinitialized = reinitialized;
    stats.full_solve_merged = true;
    ++full_solves_;
  } else {
    if (!seeds.empty()) stats = SolveWindow(seeds);
    if (full_solve_wanted_ && !job_) {
      StartFullSolve(chordal_wanted_);
      stats.full_solve_started = true;
    }
  }
  stats.full_solve_merged = stats.full_solve_merged || merged.full_solve_merged;
  stats.reinitialized = stats.reinitialized || merged.reinitialized;
  stats.solved = stats.solved || merged.full_solve_merged;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

void SlamGraph::SetPoses(const GraphSnapshot& snapshot) {
  ++structure_version_;
  for (size_t i = 0; i < snapshot.keys.size(); ++i)
    PoseToBlock(snapshot.poses[i], variables_.at(snapshot.keys[i]).block.get());
}

Status SlamGraph::ReinitializeChordal() {
  GraphSnapshot s = Snapshot();
  CAIRN_RETURN_IF_ERROR(InitializeSnapshotChordal(s));
  SetPoses(s);
  return Status::Ok();
}

SlamUpdateStats SlamGraph::SolveFull() {
  WaitForBackground();
  unconverged_.clear();
  full_solve_wanted_ = chordal_wanted_ = false;
  return Solve(static_cast<int>(options_.full_iterations), 1e9);
}

SlamUpdateStats SlamGraph::SolveFinal() {
  const SlamUpdateStats warm = SolveFull();
  const GraphSnapshot kept = Snapshot();
  if (!ReinitializeChordal().ok()) {
    SetPoses(kept);
    return warm;
  }
  SlamUpdateStats chordal = SolveFull();
  // A tie within the solver's tolerance goes to the start every robot shares.
  if (chordal.cost <= warm.cost * (1.0 + 1e-6) + 1e-12) {
    chordal.reinitialized = true;
    return chordal;
  }
  SetPoses(kept);
  return warm;
}

ceres::Manifold* SlamGraph::ManifoldOf(uint64_t key) const {
  switch (TangentSizeOf(key)) {
    case 3:
      return plane_manifold_.get();
    case 4:
      return line_manifold_.get();
    default:
      return manifold_.get();
  }
}

Expected<Pose3> SlamGraph::Pose(uint64_t key) const {
  auto it = variables_.find(key);
  if (it == variables_.end()) return NotFoundError("no variable " + std::to_string(key));
  return BlockToPose(it->second.block.get());
}

Expected<Pose3> SlamGraph::GlobalPose(char robot, const Pose3& T_s_x) const {
  auto it = latest_submap_.find(robot);
  if (it == latest_submap_.end()) return NotFoundError(std::string("no submap of robot ") + robot);
  return *Pose(it->second) * T_s_x;
}

bool SlamGraph::Tied(uint64_t key) const {
  const auto it = variables_.find(key);
  return it != variables_.end() && it->second.component == own_component_;
}

std::vector<uint64_t> SlamGraph::Unconnected() const {
  std::vector<uint64_t> out;
  for (const auto& [key, v] : variables_) {
    if (v.component != own_component_) out.push_back(key);
  }
  return out;
}

Status SlamGraph::PlaceComponent(uint64_t key, const Pose3& correction) {
  auto it = variables_.find(key);
  if (it == variables_.end()) return NotFoundError("no variable " + std::to_string(key));
  if (own_component_ < 0 || it->second.component == own_component_) {
    return InvalidArgumentError("variable " + std::to_string(key) + " is not in a floating component");
  }
  JoinComponents(own_component_, it->second.component, correction);
  return Status::Ok();
}

std::vector<uint64_t> SlamGraph::VariableKeys() const {
  std::vector<uint64_t> keys;
  keys.reserve(variables_.size());
  for (const auto& [key, v] : variables_) keys.push_back(key);
  return keys;
}

double SlamGraph::Chi2() const {
  double chi2 = 0.0;
  for (const auto& f : factors_) chi2 += FactorChi2(f);
  return chi2;
}

double SlamGraph::FactorChi2(const SlamFactor& f) const {
  const Pose3 a = *Pose(f.a);
  if (f.kind == FactorKind::kAbsolutePosition) {
    const Eigen::Vector3d e = a.t - f.position;
    return e.dot(f.position_information * e);
  }
  if (f.kind == FactorKind::kPlaneObservation) {
    const Eigen::Vector3d e = PlaneObservationResidual(f.plane, f.plane_information).Error(a, *Pose(f.b));
    return e.dot(f.plane_information * e);
  }
  if (f.kind == FactorKind::kLineObservation) {
    const Eigen::Vector4d e =
        LineObservationResidual(f.line_point, f.line_direction, f.line_information).Error(a, *Pose(f.b));
    return e.dot(f.line_information * e);
  }
  if (f.kind == FactorKind::kGnssPosition) {
    const Pose3 x = *Pose(f.b);
    const Eigen::Vector3d e = a.R().transpose() * (x.t + x.R() * f.antenna - a.t) - f.position;
    return e.dot(f.position_information * e);
  }
  const Vector6d e = IsUnary(f.kind) ? GeodesicError(Pose3(), a, f.z) : GeodesicError(a, *Pose(f.b), f.z);
  return e.dot(f.information * e);
}

Expected<std::vector<Matrix6d>> SlamGraph::Covariances(const std::vector<uint64_t>& keys) {
  if (factors_.size() != covariance_factor_count_) covariance_cache_.clear();
  std::vector<uint64_t> stale;
  for (uint64_t key : keys) {
    if (!HasVariable(key)) return NotFoundError("no variable " + std::to_string(key));
    auto it = covariance_cache_.find(key);
    const Pose3 now = *Pose(key);
    if (it != covariance_cache_.end() &&
        (it->second.first.t - now.t).norm() <= options_.covariance_translation_change &&
        it->second.first.q.angularDistance(now.q) <= options_.covariance_rotation_change) {
      continue;
    }
    stale.push_back(key);
  }
  if (!stale.empty()) {
    // All blocks' marginals come out of one selected inversion, so refresh every stale key at once.
    auto covariance = MarginalCovariance::FromProblem(*problem_);
    if (!covariance.ok()) return covariance.status();
    if (Status s = covariance->Compute(); !s.ok()) return s.WithContext("covariance");
    ++covariance_computations_;
    for (uint64_t key : stale) {
      const int i = covariance->IndexOf(variables_.at(key).block.get());
      Matrix6d c = i < 0 ? Matrix6d::Zero() : covariance->Marginal(i);  // gauge: 0
      if (const int n = TangentSizeOf(key); n < 6) {
        // A landmark's own tangent (plane: rx, ry, tz; line: rx, ry, tx, ty), the rest unused.
        c.bottomRows(6 - n).setZero();
        c.rightCols(6 - n).setZero();
      } else {
        // Ceres' quaternion tangent is half the rotation vector: scale the rotation rows and
        // columns by 2 so callers get radians.
        c.bottomRows<3>() *= 2.0;
        c.rightCols<3>() *= 2.0;
      }
      covariance_cache_[key] = {*Pose(key), c};
    }
    covariance_factor_count_ = factors_.size();
  }
  std::vector<Matrix6d> out;
  for (uint64_t key : keys) out.push_back(covariance_cache_.at(key).second);
  return out;
}

}  // namespace cairn
