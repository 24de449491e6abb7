#include "estimation/slam_graph.h"

#include <chrono>

#include <ceres/ceres.h>

#include "estimation/chordal_initializer.h"
#include "estimation/marginal_covariance.h"
#include "estimation/pose_factors.h"
#include "estimation/so3.h"

namespace cairn {

bool IsUnary(FactorKind kind) {
  return kind == FactorKind::kPrior || kind == FactorKind::kAbsolutePose ||
         kind == FactorKind::kAbsolutePosition;
}

bool IsRobustFactor(FactorKind kind) {
  return kind == FactorKind::kDetection || kind == FactorKind::kLandmark || kind == FactorKind::kMatch ||
         kind == FactorKind::kAbsolutePose || kind == FactorKind::kAbsolutePosition;
}

namespace {

Status CheckKinds(const SlamFactor& f, char own_robot) {
  using K = VariableKind;
  const K ka = KindOfKey(f.a), kb = KindOfKey(f.b);
  const bool same_robot = RobotOfVariable(f.a) == RobotOfVariable(f.b);
  auto is = [](K k) { return k == K::kRobotPose || k == K::kSubmap || k == K::kLandmark; };
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
  }
  if (!ok) return InvalidArgumentError("factor kind does not fit its variables");
  if (f.kind == FactorKind::kAbsolutePosition) {
    if (f.position_information.llt().info() != Eigen::Success) {
      return InvalidArgumentError("position information is not positive definite");
    }
  } else if (f.information.llt().info() != Eigen::Success) {
    return InvalidArgumentError("information is not positive definite");
  }
  return Status::Ok();
}

}  // namespace

SlamGraph::SlamGraph(const SlamGraphOptions& options)
    : options_(options), manifold_(MakePoseManifold()) {
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

SlamGraph::Variable& SlamGraph::CreateVariable(uint64_t key, const Pose3& initial, int component) {
  Variable& v = variables_[key];
  v.block.reset(new double[7]);
  PoseToBlock(initial, v.block.get());
  v.component = component;
  problem_->AddParameterBlock(v.block.get(), 7, manifold_.get());
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
    CreateVariable(key, pose, own_component_);
  } else if (it->second.component != own_component_) {
    const Pose3 correction = pose * BlockToPose(it->second.block.get()).Inverse();
    JoinComponents(own_component_, it->second.component, correction);
  }
}

void SlamGraph::Insert(const SlamFactor& f) {
  ceres::CostFunction* cost = nullptr;
  ceres::LossFunction* loss = IsRobustFactor(f.kind) ? cauchy_.get() : nullptr;
  ceres::ResidualBlockId id = nullptr;
  if (f.kind == FactorKind::kPrior || f.kind == FactorKind::kAbsolutePose) {
    AnchorToWorld(f.a, f.z);
    cost = AbsolutePoseResidual::Create(f.z, f.information);
    id = problem_->AddResidualBlock(cost, loss, variables_.at(f.a).block.get());
  } else if (f.kind == FactorKind::kAbsolutePosition) {
    // Translates a floating component onto the fix but keeps it floating: one position does not
    // fix its orientation.
    Variable& v = variables_.at(f.a);
    if (v.component != own_component_) {
      const Pose3 here = BlockToPose(v.block.get());
      const Pose3 shift{f.position - here.t, Eigen::Quaterniond::Identity()};
      for (uint64_t key : components_[v.component]) {
        double* b = variables_.at(key).block.get();
        PoseToBlock(shift * BlockToPose(b), b);
      }
    }
    cost = AbsolutePositionResidual::Create(f.position, f.position_information);
    id = problem_->AddResidualBlock(cost, loss, v.block.get());
  } else {
    const bool has_a = HasVariable(f.a), has_b = HasVariable(f.b);
    if (!has_a && !has_b) {
      const int c = next_component_++;
      CreateVariable(f.a, Pose3(), c);
      CreateVariable(f.b, f.z, c);
    } else if (!has_b) {
      const Variable& a = variables_.at(f.a);
      CreateVariable(f.b, BlockToPose(a.block.get()) * f.z, a.component);
    } else if (!has_a) {
      const Variable& b = variables_.at(f.b);
      CreateVariable(f.a, BlockToPose(b.block.get()) * f.z.Inverse(), b.component);
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
    cost = RelativePoseResidual::Create(f.z, f.information);
    id = problem_->AddResidualBlock(cost, loss, variables_.at(f.a).block.get(), variables_.at(f.b).block.get());
  }
  double c = 0.0;
  problem_->EvaluateResidualBlock(id, true, &c, nullptr, nullptr);
  new_cost_ += c;
  factors_.push_back(f);
}

SlamUpdateStats SlamGraph::Solve(int iterations, double seconds) {
  SlamUpdateStats stats;
  if (problem_->NumResidualBlocks() == 0) return stats;
  const auto start = std::chrono::steady_clock::now();
  ceres::Solver::Options o;
  o.linear_solver_type = ceres::SPARSE_NORMAL_CHOLESKY;
  o.max_num_iterations = iterations;
  o.max_solver_time_in_seconds = seconds;
  o.function_tolerance = 1e-10;
  o.gradient_tolerance = 1e-12;
  o.parameter_tolerance = 1e-10;
  o.num_threads = 1;
  ceres::Solver::Summary summary;
  ceres::Solve(o, problem_.get(), &summary);
  new_cost_ = 0.0;
  unconverged_ = summary.termination_type != ceres::CONVERGENCE;
  stats.solved = true;
  stats.iterations = static_cast<int>(summary.iterations.size()) - 1;
  stats.cost = summary.final_cost;
  stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return stats;
}

SlamUpdateStats SlamGraph::Update() {
  if (new_cost_ <= options_.update_min_cost && !unconverged_) return {};
  if (options_.reinitialize_cost > 0.0 && new_cost_ > options_.reinitialize_cost) {
    const auto start = std::chrono::steady_clock::now();
    const bool reinitialized = ReinitializeChordal().ok();
    SlamUpdateStats stats = SolveFull();
    stats.reinitialized = reinitialized;
    stats.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    return stats;
  }
  return Solve(static_cast<int>(options_.update_iterations), options_.update_seconds);
}

Status SlamGraph::ReinitializeChordal() {
  PoseGraph g;
  // Anchors first: InitializeChordal keeps the first vertex of each component.
  for (const auto& f : factors_) {
    if (f.kind == FactorKind::kPrior || f.kind == FactorKind::kAbsolutePose) g.SetVertex(f.a, *Pose(f.a));
  }
  for (const auto& [key, v] : variables_) {
    if (v.gauge) g.SetVertex(key, *Pose(key));
  }
  for (const auto& [key, v] : variables_) {
    if (!g.HasVertex(key)) g.SetVertex(key, *Pose(key));
  }
  for (const auto& f : factors_) {
    if (IsUnary(f.kind)) continue;
    PoseGraphEdge e;
    e.from = f.a;
    e.to = f.b;
    e.T_from_to = f.z;
    e.information = f.information;
    PoseGraph::SetIsotropicWeights(e);
    g.AddEdge(e);
  }
  CAIRN_RETURN_IF_ERROR(InitializeChordal(g));
  for (size_t i = 0; i < g.num_vertices(); ++i) PoseToBlock(g.poses()[i], variables_.at(g.ids()[i]).block.get());
  return Status::Ok();
}

SlamUpdateStats SlamGraph::SolveFull() { return Solve(static_cast<int>(options_.full_iterations), 1e9); }

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

std::vector<uint64_t> SlamGraph::Unconnected() const {
  std::vector<uint64_t> out;
  for (const auto& [key, v] : variables_) {
    if (v.component != own_component_) out.push_back(key);
  }
  return out;
}

std::vector<uint64_t> SlamGraph::VariableKeys() const {
  std::vector<uint64_t> keys;
  keys.reserve(variables_.size());
  for (const auto& [key, v] : variables_) keys.push_back(key);
  return keys;
}

double SlamGraph::Chi2() const {
  double chi2 = 0.0;
  for (const auto& f : factors_) {
    const Pose3 a = *Pose(f.a);
    if (f.kind == FactorKind::kAbsolutePosition) {
      const Eigen::Vector3d e = a.t - f.position;
      chi2 += e.dot(f.position_information * e);
      continue;
    }
    const Vector6d e = IsUnary(f.kind) ? GeodesicError(Pose3(), a, f.z) : GeodesicError(a, *Pose(f.b), f.z);
    chi2 += e.dot(f.information * e);
  }
  return chi2;
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
      covariance_cache_[key] = {*Pose(key), i < 0 ? Matrix6d::Zero() : covariance->Marginal(i)};  // gauge: 0
    }
    covariance_factor_count_ = factors_.size();
  }
  std::vector<Matrix6d> out;
  for (uint64_t key : keys) out.push_back(covariance_cache_.at(key).second);
  return out;
}

}  // namespace cairn
