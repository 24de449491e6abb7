#include "estimation/graph/topology_builder.h"

#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

Matrix6d InverseCovariance(const Matrix6d& cov) { return cov.inverse(); }

// Eq. 4.9: the difference of two covariances, kept positive definite.
Matrix6d ClampedDifference(const Matrix6d& later, const Matrix6d& earlier) {
  Vector6d ev;
  Matrix6d V;
  // Without convergence (non-finite input), the difference is not usable: the floor alone.
  if (!SymmetricEigen(0.5 * ((later - earlier) + (later - earlier).transpose()), &ev, &V)) {
    return Matrix6d::Identity() * 1e-10;
  }
  return V * ev.cwiseMax(1e-10).asDiagonal() * V.transpose();
}

}  // namespace

TopologyBuilder::TopologyBuilder(Topology topology, char robot) : topology_(topology), robot_(robot) {}

std::vector<SlamFactor> TopologyBuilder::Start(bool own, const Matrix6d& prior_information) {
  std::vector<SlamFactor> out;
  submap_ = 0;
  if (topology_ == Topology::kSequential) {
    last_key_ = VariableKey(VariableKind::kRobotPose, robot_, next_pose_++);
    submap_keys_.assign(1, last_key_);
  }
  if (own) {
    SlamFactor prior;
    prior.kind = topology_ == Topology::kFilter ? FactorKind::kPrior : FactorKind::kAbsolutePose;
    prior.a = SubmapKey(0);
    prior.information = prior_information;
    out.push_back(prior);
  }
  return out;
}

uint64_t TopologyBuilder::SubmapKey(uint64_t index) const {
  if (topology_ == Topology::kFilter) return VariableKey(VariableKind::kSubmap, robot_, index);
  return submap_keys_.at(index);
}

std::vector<SlamFactor> TopologyBuilder::ChainTo(const Pose3& T_odom_x, const Matrix6d& cov, uint64_t* key) {
  SlamFactor u;
  u.kind = FactorKind::kOdometry;
  u.a = last_key_;
  u.b = VariableKey(VariableKind::kRobotPose, robot_, next_pose_++);
  u.z = last_pose_.Inverse() * T_odom_x;                           // eq. 4.8
  u.information = InverseCovariance(ClampedDifference(cov, last_cov_));  // eq. 4.9
  last_key_ = u.b;
  last_pose_ = T_odom_x;
  last_cov_ = cov;
  if (key != nullptr) *key = u.b;
  return {u};
}

std::vector<SlamFactor> TopologyBuilder::FrameSwitch(const Pose3& T_old_new, const Matrix6d& covariance) {
  ++submap_;
  if (topology_ == Topology::kFilter) {
    SlamFactor w;
    w.kind = FactorKind::kFrameSwitch;
    w.a = SubmapKey(submap_ - 1);
    w.b = SubmapKey(submap_);
    w.z = T_old_new;
    w.information = InverseCovariance(covariance);
    return {w};
  }
  T_odom_s_ = T_odom_s_ * T_old_new;
  cov_s_ += covariance;
  uint64_t key = 0;
  auto out = ChainTo(T_odom_s_, cov_s_, &key);
  submap_keys_.push_back(key);
  return out;
}

std::vector<SlamFactor> TopologyBuilder::PoseEstimate(const Pose3& T_s_x, const Matrix6d& covariance, uint64_t* key) {
  if (topology_ == Topology::kFilter) {
    SlamFactor v;
    v.kind = FactorKind::kFilterEstimate;
    v.a = SubmapKey(submap_);
    v.b = VariableKey(VariableKind::kRobotPose, robot_, next_pose_++);
    v.z = T_s_x;
    v.information = InverseCovariance(covariance);
    if (key != nullptr) *key = v.b;
    return {v};
  }
  return ChainTo(T_odom_s_ * T_s_x, cov_s_ + covariance, key);
}

}  // namespace cairn
