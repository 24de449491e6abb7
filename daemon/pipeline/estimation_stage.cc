#include "daemon/pipeline/estimation_stage.h"

#include "estimation/math/symmetric_eigen.h"

namespace cairn {

EstimationStage::EstimationStage(const FilterOptions& options, const ImuCalibration& imu,
                                 const WheelCalibration& wheels, SpscQueue<FrameEstimate>* estimates)
    : filter_(options, imu, wheels), estimates_(estimates) {
  T_first_frame_.fill(Eigen::Isometry3d::Identity());
}

void EstimationStage::OnImu(const ImuSample& s) {
  filter_.Propagate(s);
  FlushPending();
}

void EstimationStage::OnWheel(const WheelOdometrySample& s) { filter_.ApplyWheelOdometry(s); }

void EstimationStage::OnFrame(Timestamp time) {
  const CloneRequest c = filter_.Clone(time);
  if (c.id == kNoClone) {
    ++report_.clones_failed;
    return;
  }
  // The ring holds far more entries than the filter holds clones: an overwritten entry's clone
  // is long marginalized.
  clones_[next_clone_slot_] = CloneEntry{time, c.id};
  next_clone_slot_ = (next_clone_slot_ + 1) % clones_.size();
}

CloneId EstimationStage::FindClone(Timestamp t) const {
  for (const CloneEntry& e : clones_) {
    if (e.id != kNoClone && e.time == t) return e.id;
  }
  return kNoClone;
}

void EstimationStage::Release(Timestamp t) {
  for (CloneEntry& e : clones_) {
    if (e.id != kNoClone && e.time == t) {
      filter_.ReleaseClone(e.id);
      e.id = kNoClone;
    }
  }
}

void EstimationStage::OnVoResult(const VoResult& r) {
  ++report_.vo_results;
  PendingFrame f;
  f.time = r.time;
  f.status = r.status;
  if (r.status == VoStatus::kOk) {
    f.keyframe_time = r.keyframe_time;
    const CloneId kf = FindClone(r.keyframe_time), cur = FindClone(r.time);
    if (kf == kNoClone || cur == kNoClone) {
      ++report_.vo_missing_clone;
      f.missing = kf == kNoClone;
    } else {
      const FilterResult res = filter_.ApplyRelativePose(kf, cur, r.T_kf_cur, r.covariance);
      if (res == FilterResult::kApplied || res == FilterResult::kPending) {
        ++report_.vo_updates_applied;
      } else {
        ++report_.vo_updates_rejected;
        if (res == FilterResult::kRejectedUnknownClone) f.missing = true;
      }
    }
  }
  // Clones nobody will reference again are marginalized.
  if (!r.new_keyframe) Release(r.time);
  for (int i = 0; i < r.removed_count; ++i) Release(r.removed[static_cast<size_t>(i)]);
  if (pending_end_ - pending_begin_ == pending_.size()) {
    Emit(pending_[pending_begin_ % pending_.size()]);  // overdue: emit what we have
    ++pending_begin_;
  }
  pending_[pending_end_++ % pending_.size()] = f;
  FlushPending();
}

void EstimationStage::FlushPending() {
  while (pending_begin_ < pending_end_) {
    const PendingFrame& f = pending_[pending_begin_ % pending_.size()];
    // Wait until the IMU data reaches the frame (a pending update is applied by then).
    if (filter_.initialized() && filter_.state().time < f.time) break;
    Emit(f);
    ++pending_begin_;
  }
}

void EstimationStage::Emit(const PendingFrame& f) {
  FrameEstimate e;
  e.time = f.time;
  e.vo_status = f.status;
  e.keyframe_clone_missing = f.missing;
  e.keyframe_time = f.keyframe_time;
  PoseSample pose;
  if (filter_.initialized() && filter_.PoseAt(f.time, &pose) && filter_.frame_id() - pose.frame_id < T_first_frame_.size()) {
    e.valid = true;
    e.frame_id = pose.frame_id;
    e.T_frame_body = pose.T_frame_body;
    e.T_first_body = T_first_frame_[pose.frame_id % T_first_frame_.size()] * pose.T_frame_body;
    const Eigen::Matrix3d position_cov = pose.covariance.topLeftCorner<3, 3>();
    e.position_sigma = std::sqrt(std::max(0.0, SymmetricEigenvalues(position_cov).maxCoeff()));
    e.position_covariance = pose.covariance.topLeftCorner<3, 3>();
    e.pose_covariance = pose.covariance;
  }
  if (estimates_->TryPush(e)) {
    ++report_.estimates_emitted;
  } else {
    ++report_.estimates_dropped;
  }
  if (mapping_estimates_ != nullptr && !mapping_estimates_->TryPush(e)) ++report_.mapping_estimates_dropped;
  if (graph_inputs_ != nullptr && e.valid) {
    graph_input_.kind = GraphInput::Kind::kEstimate;
    graph_input_.estimate = e;
    if (!graph_inputs_->TryPush(graph_input_)) ++report_.graph_inputs_dropped;
  }
}

void EstimationStage::OnFrameSwitch(const FilterSwitchRequest& request) {
  const uint64_t old_id = filter_.frame_id();
  const FrameSwitchResult r = filter_.RequestFrameSwitch();
  if (r.result != FilterResult::kApplied) return;
  T_first_frame_[r.new_frame_id % T_first_frame_.size()] =
      T_first_frame_[old_id % T_first_frame_.size()] * r.transform.T_old_new;
  ++report_.frame_switches;
  ++report_.switch_reasons[static_cast<size_t>(request.reason)];
  const FrameSwitchEvent event{r.time, r.old_frame_id, r.new_frame_id, r.transform};
  if (switch_events_ != nullptr && !switch_events_->TryPush(event)) ++report_.switch_events_dropped;
  if (graph_inputs_ != nullptr) {
    graph_input_.kind = GraphInput::Kind::kFrameSwitch;
    graph_input_.frame_switch = event;
    if (!graph_inputs_->TryPush(graph_input_)) ++report_.graph_inputs_dropped;
  }
}

EstimationReport EstimationStage::report() const {
  EstimationReport r = report_;
  r.filter = filter_.counters();
  r.initialized = filter_.initialized();
  return r;
}

}  // namespace cairn
