#include "estimation/filter/local_reference_filter.h"

#include <algorithm>
#include <cmath>
#include <variant>

#include "estimation/filter/filter_kernels.h"
#include "estimation/filter/filter_update.h"
#include "estimation/filter/wheel_velocity.h"
#include "estimation/math/small_cholesky.h"
#include "estimation/math/so3.h"

namespace cairn {
namespace {

template <int N>
bool CovarianceOk(const Eigen::Matrix<double, N, N>& c) {
  if (!c.allFinite()) return false;
  if ((c - c.transpose()).cwiseAbs().maxCoeff() > 1e-9 * (1.0 + c.cwiseAbs().maxCoeff())) return false;
  return small_cholesky::PositiveDefinite<N>(c);
}

FilterResult FromOutcome(UpdateOutcome o) {
  switch (o) {
    case UpdateOutcome::kApplied: return FilterResult::kApplied;
    case UpdateOutcome::kBadCovariance: return FilterResult::kRejectedBadCovariance;
    case UpdateOutcome::kGated: return FilterResult::kRejectedGate;
  }
  return FilterResult::kRejectedBadCovariance;
}

}  // namespace

LocalReferenceFilter::LocalReferenceFilter(const FilterOptions& options, const ImuCalibration& imu,
                                           const WheelCalibration& wheels)
    : options_(options),
      calibration_(imu),
      wheels_(wheels),
      T_imu_body_(imu.T_body_imu.inverse()),
      propagator_(ImuNoise::FromCalibration(imu), options.gravity),
      initializer_(options),
      imu_(static_cast<size_t>(std::clamp<int64_t>(options.imu_buffer, 16, kMaxImuBuffer))),
      events_(static_cast<size_t>(std::clamp<int64_t>(options.event_log, 16, kMaxEventLog))),
      snapshots_(static_cast<size_t>(std::clamp<int64_t>(options.snapshots, 2, kMaxSnapshots))),
      history_(static_cast<size_t>(std::clamp<int64_t>(options.history, 2, kMaxHistory))) {
  options_.max_clones = std::clamp<int64_t>(options_.max_clones, 2, kMaxClones);
  // Written once now: their pages were otherwise first written by the first frame switch, which
  // then took about 200 us instead of 40 (page faults; memory locking did not prevent them).
  scratch_a_.setZero();
  scratch_b_.setZero();
}

void LocalReferenceFilter::Initialize(Timestamp time, const Eigen::Vector3d& p,
                                      const Eigen::Vector3d& v, const Eigen::Quaterniond& q,
                                      const Eigen::Vector3d& ba, const Eigen::Vector3d& bg,
                                      const Eigen::Matrix<double, 15, 15>& covariance,
                                      const ImuSample& first_sample) {
  state_.time = time;
  state_.p = p;
  state_.v = v;
  state_.q = q.normalized();
  state_.ba = ba;
  state_.bg = bg;
  state_.accel = first_sample.accel;
  state_.gyro = first_sample.gyro;
  state_.clones.fill(CloneSlot{});
  state_.P.setZero();
  state_.phi.setIdentity();
  state_.cross_current.fill(false);
  state_.cross_pending = false;
  state_.pending_transition = CoreTransitionProduct{};
  state_.P.topLeftCorner<15, 15>() = 0.5 * (covariance + covariance.transpose());
  initialized_ = true;
  have_last_imu_ = true;
  last_imu_time_ = time;
  far_future_run_ = 0;

  if (imu_end_ - imu_begin_ == imu_.size()) ++imu_begin_;
  imu_[imu_end_ % imu_.size()] = first_sample;
  const uint64_t k = imu_end_++;
  history_begin_ = k;
  WriteHistory(k);
  ResetReplayWindow(imu_end_);
}

FilterResult LocalReferenceFilter::Propagate(const ImuSample& sample) {
  if (!sample.accel.allFinite() || !sample.gyro.allFinite()) {
    ++counters_.imu_not_finite;
    return FilterResult::kRejectedNotFinite;
  }
  bool resync = false;
  if (have_last_imu_) {
    if (sample.time == last_imu_time_) {
      ++counters_.imu_duplicate;
      return FilterResult::kRejectedDuplicate;
    }
    if (sample.time < last_imu_time_) {
      ++counters_.imu_out_of_order;
      return FilterResult::kRejectedOutOfOrder;
    }
    if ((sample.time - last_imu_time_).seconds() > options_.max_imu_gap) {
      // A run of samples that agree with each other but not with the past is a real gap.
      const bool continues = far_future_run_ > 0 && sample.time > far_future_last_ &&
                             (sample.time - far_future_last_).seconds() <= options_.max_imu_gap;
      far_future_run_ = continues ? far_future_run_ + 1 : 1;
      far_future_last_ = sample.time;
      if (far_future_run_ < options_.imu_resync_samples) {
        ++counters_.imu_far_future;
        return FilterResult::kRejectedFarFuture;
      }
      resync = true;
      ++counters_.imu_resyncs;
    }
  }
  far_future_run_ = 0;
  have_last_imu_ = true;
  last_imu_time_ = sample.time;

  if (!initialized_) {
    if (resync) initializer_.Reset();
    if (!initializer_.Add(sample)) return FilterResult::kInitializing;
    Eigen::Matrix<double, 15, 15> cov = Eigen::Matrix<double, 15, 15>::Zero();
    const double s_rp = options_.init_sigma_roll_pitch;
    cov.block<3, 3>(kV, kV).diagonal().setConstant(options_.init_sigma_velocity * options_.init_sigma_velocity);
    // Roll and pitch uncertain, yaw defines the frame (zero uncertainty); expressed in the IMU
    // frame through the attitude.
    const Eigen::Quaterniond q = initializer_.Attitude();
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Matrix3d cov_world = Eigen::Vector3d(s_rp * s_rp, s_rp * s_rp, 0.0).asDiagonal();
    cov.block<3, 3>(kTheta, kTheta) = R.transpose() * cov_world * R;
    cov.block<3, 3>(kBa, kBa).diagonal().setConstant(options_.init_sigma_accel_bias * options_.init_sigma_accel_bias);
    cov.block<3, 3>(kBg, kBg).diagonal().setConstant(options_.init_sigma_gyro_bias * options_.init_sigma_gyro_bias);
    Initialize(sample.time, Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), q,
               Eigen::Vector3d::Zero(), initializer_.mean_gyro(), cov, sample);
    ++counters_.imu_accepted;
    return FilterResult::kApplied;
  }

  if (imu_end_ - imu_begin_ == imu_.size()) ++imu_begin_;
  imu_[imu_end_ % imu_.size()] = sample;
  const uint64_t k = imu_end_++;
  ++counters_.imu_accepted;
  if (resync) {
    // Restart integration at the new time; the unobserved interval adds its process noise.
    const double gap = (sample.time - state_.time).seconds();
    const ImuNoise n = ImuNoise::FromCalibration(calibration_);
    state_.P.block<3, 3>(kV, kV).diagonal().array() += n.accel_noise_density * n.accel_noise_density * gap;
    state_.P.block<3, 3>(kTheta, kTheta).diagonal().array() += n.gyro_noise_density * n.gyro_noise_density * gap;
    state_.P.block<3, 3>(kBa, kBa).diagonal().array() += n.accel_random_walk * n.accel_random_walk * gap;
    state_.P.block<3, 3>(kBg, kBg).diagonal().array() += n.gyro_random_walk * n.gyro_random_walk * gap;
    state_.time = sample.time;
    state_.accel = sample.accel;
    state_.gyro = sample.gyro;
    WriteHistory(k);
    ResetReplayWindow(imu_end_);
    return FilterResult::kApplied;
  }
  Step(k);
  return FilterResult::kApplied;
}

void LocalReferenceFilter::Step(uint64_t k) {
  const ImuSample& s = ImuAt(k);
  current_imu_seq_ = k;
  while (events_.next_seq() < events_.end_seq() && events_.at(events_.next_seq()).time <= s.time) {
    FilterEvent& e = events_.at(events_.next_seq());
    if (e.time > state_.time) {
      // Readings are linear in time between samples: interpolate at the event.
      const double a = (e.time - state_.time).seconds() / (s.time - state_.time).seconds();
      const Eigen::Vector3d accel = state_.accel + a * (s.accel - state_.accel);
      const Eigen::Vector3d gyro = state_.gyro + a * (s.gyro - state_.gyro);
      propagator_.Propagate(state_, e.time, accel, gyro);
    }
    events_.Advance();
    e.result = ProcessEvent(e);
  }
  propagator_.Propagate(state_, s.time, s.accel, s.gyro);
  WriteHistory(k);
}

void LocalReferenceFilter::ProcessNow(const FilterEvent& e) {
  const uint64_t pos = events_.next_seq();
  events_.Insert(pos, e);
  FilterEvent& stored = events_.at(pos);
  events_.Advance();
  current_imu_seq_ = imu_end_;
  stored.result = ProcessEvent(stored);
}

FilterResult LocalReferenceFilter::Submit(FilterEvent e) {
  if (!initialized_) return FilterResult::kNotInitialized;
  if ((e.time - state_.time).seconds() > options_.max_event_lead) {
    return FilterResult::kRejectedFarFuture;
  }
  if (!events_.MakeRoom()) return FilterResult::kRejectedBufferFull;
  const uint64_t pos = events_.InsertPosition(e.time);

  if (e.time > state_.time) {
    events_.Insert(pos, e);
    return FilterResult::kPending;
  }
  if (e.time == state_.time && pos == events_.next_seq()) {
    ProcessNow(e);
    return events_.at(events_.next_seq() - 1).result;
  }

  // Late: restart from the newest saved state before the event's place, if still buffered.
  uint64_t found = snap_end_;
  if ((state_.time - e.time).seconds() <= options_.max_update_delay) {
    for (uint64_t j = snap_end_; j > snap_begin_; --j) {
      const Snapshot& sn = snapshots_[(j - 1) % snapshots_.size()];
      if (sn.event_seq <= pos && sn.head.time <= e.time) {
        if (sn.event_seq >= events_.begin_seq() && sn.imu_seq >= imu_begin_) found = j - 1;
        break;
      }
    }
  }
  if (found == snap_end_) {
    if (!std::holds_alternative<RelativePoseEvent>(e.data)) return FilterResult::kRejectedTooOld;
    // Both clones are still in the state: apply it now, at the present linearization point.
    e.time = state_.time;
    ProcessNow(e);
    const FilterResult r = events_.at(events_.next_seq() - 1).result;
    if (r == FilterResult::kApplied) ++counters_.updates_direct;
    return r;
  }

  events_.Insert(pos, e);
  const Snapshot& sn = snapshots_[found % snapshots_.size()];
  UnpackCovariance(sn.P, sn.head.cross_pending, state_);  // before the head: uses the live flag
  static_cast<FilterStateHead&>(state_) = sn.head;
  events_.Rewind(sn.event_seq);
  snap_end_ = found + 1;
  replaying_ = true;
  replay_saved_ = false;
  ++counters_.replays;
  for (uint64_t k = sn.imu_seq; k < imu_end_; ++k) {
    Step(k);
    ++counters_.replayed_imu_samples;
  }
  // Events at exactly the newest sample time are processed by the last Step already.
  replaying_ = false;
  return events_.at(pos).result;
}

FilterResult LocalReferenceFilter::ProcessEvent(const FilterEvent& e) {
  if (const auto* clone = std::get_if<CloneEvent>(&e.data)) {
    if (SlotOf(clone->clone) < 0) AddClone(clone->clone);
    // A replay saves only the first clone it passes (where the next late measurement, for the
    // following frame, starts); the later saved states it invalidates are dropped, and a
    // measurement for one of those frames replays from that first one.
    if (!replaying_ || !replay_saved_) PushSnapshot(current_imu_seq_);
    replay_saved_ = true;
    return FilterResult::kApplied;
  }
  if (const auto* release = std::get_if<ReleaseEvent>(&e.data)) {
    const int slot = SlotOf(release->clone);
    if (slot < 0) return FilterResult::kRejectedUnknownClone;
    Marginalize(slot);
    return FilterResult::kApplied;
  }
  if (const auto* pose = std::get_if<RelativePoseEvent>(&e.data)) {
    RelativePoseMeasurement m;
    m.keyframe_slot = SlotOf(pose->keyframe);
    m.current_slot = SlotOf(pose->current);
    if (m.keyframe_slot < 0 || m.current_slot < 0) return FilterResult::kRejectedUnknownClone;
    m.t_k_c = pose->t_k_c;
    m.q_k_c = pose->q_k_c;
    m.covariance = pose->covariance;
    const FilterResult r = FromOutcome(ApplyRelativePoseUpdate(state_, m, options_.relative_pose_gate));
    if (r == FilterResult::kApplied) {
      state_.clones[static_cast<size_t>(m.keyframe_slot)].last_used = state_.time;
    }
    return r;
  }
  if (const auto* wheel = std::get_if<WheelEvent>(&e.data)) {
    // Third row: the body's vertical velocity is zero (used when nonholonomic).
    const Eigen::Vector3d velocity(wheel->v_xy.x(), wheel->v_xy.y(), 0.0);
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    cov.topLeftCorner<2, 2>() = wheel->covariance;
    cov(2, 2) = options_.nonholonomic_sigma * options_.nonholonomic_sigma;
    return FromOutcome(ApplyBodyVelocityUpdate(state_, T_imu_body_.linear(), T_imu_body_.translation(),
                                               velocity, cov, options_.nonholonomic ? 3 : 2));
  }
  if (const auto* position = std::get_if<PositionEvent>(&e.data)) {
    return FromOutcome(ApplyPositionUpdate(state_, position->p_frame_imu, position->covariance));
  }
  return FilterResult::kRejectedDisabled;
}

int LocalReferenceFilter::SlotOf(CloneId id) const {
  if (id == kNoClone) return -1;
  for (int i = 0; i < kMaxClones; ++i) {
    if (state_.clones[static_cast<size_t>(i)].id == id) return i;
  }
  return -1;
}

int LocalReferenceFilter::active_clones() const {
  int n = 0;
  for (const CloneSlot& c : state_.clones) n += c.id != kNoClone ? 1 : 0;
  return n;
}

void LocalReferenceFilter::Marginalize(int slot) {
  // Dropping a clone's rows and columns is exact marginalization of a Gaussian; it needs nothing
  // deferred to be applied (the slot's cross block is zero in any representation).
  const int ic = CloneIndex(slot);
  state_.P.middleRows<6>(ic).setZero();
  state_.P.middleCols<6>(ic).setZero();
  state_.clones[static_cast<size_t>(slot)] = CloneSlot{};
  state_.cross_current[static_cast<size_t>(slot)] = false;
  if (!replaying_) ++counters_.clones_marginalized;
}

void LocalReferenceFilter::AddClone(CloneId id) {
  FlushTransition(state_);  // reads phi and the current cross blocks
  if (active_clones() >= options_.max_clones) {
    // Bounded: drop the least recently used clone (created or referenced as keyframe longest ago).
    int victim = -1;
    for (int i = 0; i < kMaxClones; ++i) {
      const CloneSlot& c = state_.clones[static_cast<size_t>(i)];
      if (c.id == kNoClone) continue;
      if (victim < 0) {
        victim = i;
        continue;
      }
      const CloneSlot& v = state_.clones[static_cast<size_t>(victim)];
      if (c.last_used < v.last_used || (c.last_used == v.last_used && c.id < v.id)) victim = i;
    }
    Marginalize(victim);
  }
  // Clones whose cross block is kept current cost work per IMU sample: bound their number.
  int current = 0;
  for (int i = 0; i < kMaxClones; ++i) current += state_.cross_current[static_cast<size_t>(i)] ? 1 : 0;
  if (current >= kMaxCurrentCrossBlocks) MaterializeCross(state_);

  int slot = 0;
  while (state_.clones[static_cast<size_t>(slot)].id != kNoClone) ++slot;
  // The clone's error equals the current pose error [dp, dtheta]: its covariance with the core
  // is the core's p and theta rows, with another clone the p and theta columns of that clone's
  // clone-core cross block.
  const int ic = CloneIndex(slot);
  state_.P.block<3, kCoreDim>(ic, 0) = state_.P.block<3, kCoreDim>(kP, 0);
  state_.P.block<3, kCoreDim>(ic + 3, 0) = state_.P.block<3, kCoreDim>(kTheta, 0);
  // Covariances of all clones with the new one: the p and theta columns of their true
  // clone-core cross blocks, B phi^T (or B where it is current).
  Eigen::Matrix<double, kCoreDim, 6> pose_cols_phi_t;  // columns p, theta of phi^T
  pose_cols_phi_t.leftCols<3>() = state_.phi.middleRows<3>(kP).transpose();
  pose_cols_phi_t.rightCols<3>() = state_.phi.middleRows<3>(kTheta).transpose();
  Eigen::Matrix<double, kCloneDims, 6> with_new;
  kernels::MulRows<kCoreDim, 6, kernels::kSet>(with_new.data(), kCloneDims, &state_.P(kCoreDim, 0), kStateDim,
                                               kCloneDims, pose_cols_phi_t.data(), kCoreDim);
  for (int j = 0; j < kMaxClones; ++j) {
    if (j == slot || state_.clones[static_cast<size_t>(j)].id == kNoClone) continue;
    const int jc = CloneIndex(j);
    Matrix6d b;  // covariance of clone j with the new clone
    if (state_.cross_current[static_cast<size_t>(j)]) {
      const auto B = state_.P.block<6, kCoreDim>(jc, 0);
      b.leftCols<3>() = B.middleCols<3>(kP);
      b.rightCols<3>() = B.middleCols<3>(kTheta);
    } else {
      b = with_new.middleRows<6>(6 * j);
    }
    // Only the blocks on and below the block diagonal are kept current.
    if (j > slot) {
      state_.P.block<6, 6>(jc, ic) = b;
    } else {
      state_.P.block<6, 6>(ic, jc) = b.transpose();
    }
  }
  Matrix6d d;
  d.topLeftCorner<3, 3>() = state_.P.block<3, 3>(kP, kP);
  d.topRightCorner<3, 3>() = state_.P.block<3, 3>(kP, kTheta);
  d.bottomLeftCorner<3, 3>() = state_.P.block<3, 3>(kTheta, kP);
  d.bottomRightCorner<3, 3>() = state_.P.block<3, 3>(kTheta, kTheta);
  state_.P.block<6, 6>(ic, ic) = d;
  state_.cross_current[static_cast<size_t>(slot)] = true;
  MarkDeferred(state_);

  CloneSlot& c = state_.clones[static_cast<size_t>(slot)];
  c.id = id;
  c.time = state_.time;
  c.p_frame_imu = state_.p;
  c.q_frame_imu = state_.q;
  c.last_used = state_.time;
}

void LocalReferenceFilter::PushSnapshot(uint64_t imu_seq) {
  if (snap_end_ - snap_begin_ == snapshots_.size()) {
    ++snap_begin_;
    // Events before the oldest replay start are never needed again.
    events_.DropBefore(snapshots_[snap_begin_ % snapshots_.size()].event_seq);
  }
  Snapshot& sn = snapshots_[snap_end_ % snapshots_.size()];
  sn.head = static_cast<const FilterStateHead&>(state_);
  PackCovariance(state_.P, sn.P);
  sn.imu_seq = imu_seq;
  sn.event_seq = events_.next_seq();
  ++snap_end_;
}

void LocalReferenceFilter::ResetReplayWindow(uint64_t imu_seq) {
  events_.DropProcessed();
  snap_begin_ = snap_end_;
  PushSnapshot(imu_seq);
}

void LocalReferenceFilter::WriteHistory(uint64_t k) {
  PoseSample& h = history_[k % history_.size()];
  h.time = state_.time;
  h.frame_id = frame_id_;
  // T_frame_imu T_imu_body by its parts (the full 4x4 product is most of this per-sample work).
  const Eigen::Matrix3d R = state_.q.toRotationMatrix();
  h.T_frame_body.linear() = R * T_imu_body_.linear();
  h.T_frame_body.translation() = R * T_imu_body_.translation() + state_.p;
  h.covariance.topLeftCorner<3, 3>() = state_.P.block<3, 3>(kP, kP);
  h.covariance.topRightCorner<3, 3>() = state_.P.block<3, 3>(kP, kTheta);
  h.covariance.bottomLeftCorner<3, 3>() = state_.P.block<3, 3>(kTheta, kP);
  h.covariance.bottomRightCorner<3, 3>() = state_.P.block<3, 3>(kTheta, kTheta);
  history_end_ = std::max(history_end_, k + 1);
}

CloneRequest LocalReferenceFilter::Clone(Timestamp trigger_time) {
  CloneRequest out;
  if (!initialized_) return out;
  ++counters_.clones_requested;
  FilterEvent e;
  e.time = trigger_time;
  e.data = CloneEvent{next_clone_id_};
  out.result = Submit(e);
  if (out.result == FilterResult::kApplied || out.result == FilterResult::kPending) {
    out.id = next_clone_id_++;
  } else {
    ++counters_.events_rejected;
  }
  return out;
}

FilterResult LocalReferenceFilter::ReleaseClone(CloneId id) {
  if (!initialized_) return FilterResult::kNotInitialized;
  FilterEvent e;
  e.time = state_.time;
  e.data = ReleaseEvent{id};
  if (!events_.MakeRoom()) {
    ++counters_.events_rejected;
    return FilterResult::kRejectedBufferFull;
  }
  // A release takes effect now; it is logged so that replays keep it.
  ProcessNow(e);
  const FilterResult r = events_.at(events_.next_seq() - 1).result;
  if (r != FilterResult::kApplied) ++counters_.events_rejected;
  return r;
}

void LocalReferenceFilter::Count(FilterResult r, bool measurement) {
  if (r == FilterResult::kApplied || r == FilterResult::kPending) {
    if (measurement && r == FilterResult::kApplied) ++counters_.updates_applied;
    return;
  }
  if (measurement) {
    ++counters_.updates_rejected;
  } else {
    ++counters_.events_rejected;
  }
}

FilterResult LocalReferenceFilter::ApplyRelativePose(CloneId keyframe, CloneId current,
                                                     const Eigen::Isometry3d& T_kf_cur,
                                                     const Matrix6d& covariance) {
  if (!initialized_) return FilterResult::kNotInitialized;
  FilterResult r = FilterResult::kApplied;
  if (!T_kf_cur.matrix().allFinite()) r = FilterResult::kRejectedNotFinite;
  else if (!CovarianceOk(covariance)) r = FilterResult::kRejectedBadCovariance;
  if (r != FilterResult::kApplied) {
    Count(r, true);
    return r;
  }
  // The measurement belongs to the current clone's exposure time, found in the event log (the
  // clone may be gone from the live state and still be there at its exposure time), else in the
  // live state (beyond the replay window).
  Timestamp time;
  bool known = false;
  for (uint64_t s = events_.begin_seq(); s < events_.end_seq() && !known; ++s) {
    const FilterEvent& ev = events_.at(s);
    const auto* clone = std::get_if<CloneEvent>(&ev.data);
    if (clone != nullptr && clone->clone == current) {
      time = ev.time;
      known = true;
    }
  }
  const int cslot = SlotOf(current);
  if (!known && cslot >= 0) {
    time = state_.clones[static_cast<size_t>(cslot)].time;
    known = true;
  }
  if (!known) {
    Count(FilterResult::kRejectedUnknownClone, true);
    return FilterResult::kRejectedUnknownClone;
  }

  // Body-frame delta to IMU-frame delta: T_ik_ic = T_i_b T_bk_bc T_b_i.
  const Eigen::Isometry3d& T_b_i = calibration_.T_body_imu;
  const Eigen::Isometry3d T_i_b = T_b_i.inverse();
  const Eigen::Isometry3d T_imu = T_i_b * T_kf_cur * T_b_i;
  const Eigen::Matrix3d R_ib = T_i_b.linear();
  Matrix6d J = Matrix6d::Zero();
  J.topLeftCorner<3, 3>() = R_ib;
  J.topRightCorner<3, 3>() = -R_ib * T_kf_cur.linear() * so3::Skew(T_b_i.translation());
  J.bottomRightCorner<3, 3>() = R_ib;

  FilterEvent e;
  e.time = time;
  RelativePoseEvent& pose = e.data.emplace<RelativePoseEvent>();
  pose.keyframe = keyframe;
  pose.current = current;
  pose.t_k_c = T_imu.translation();
  pose.q_k_c = Eigen::Quaterniond(T_imu.linear()).normalized();
  pose.covariance = J * covariance * J.transpose();
  r = Submit(e);
  Count(r, true);
  return r;
}

FilterResult LocalReferenceFilter::ApplyWheelOdometry(const BodyVelocity& velocity) {
  if (!initialized_) {
    if (options_.wheel_enabled) initializer_.AddBodyVelocity(velocity.v_xy, velocity.covariance);
    return FilterResult::kNotInitialized;
  }
  FilterResult r = FilterResult::kApplied;
  if (!options_.wheel_enabled) r = FilterResult::kRejectedDisabled;
  else if (!velocity.v_xy.allFinite()) r = FilterResult::kRejectedNotFinite;
  else if (!CovarianceOk(velocity.covariance)) r = FilterResult::kRejectedBadCovariance;
  if (r == FilterResult::kApplied) {
    FilterEvent e;
    e.time = velocity.time;
    e.data = WheelEvent{velocity.v_xy, velocity.covariance};
    r = Submit(e);
  }
  Count(r, true);
  return r;
}

FilterResult LocalReferenceFilter::ApplyWheelOdometry(const WheelOdometrySample& sample) {
  BodyVelocity v;
  if (options_.wheel_enabled && !WheelBodyVelocity(sample, wheels_, options_.wheel_lateral_sigma, &v)) {
    if (!initialized_) return FilterResult::kNotInitialized;
    Count(FilterResult::kRejectedInvalid, true);
    return FilterResult::kRejectedInvalid;
  }
  return ApplyWheelOdometry(v);
}

FilterResult LocalReferenceFilter::ApplyPosition(Timestamp time, const Eigen::Vector3d& p,
                                                 const Eigen::Matrix3d& cov) {
  if (!initialized_) return FilterResult::kNotInitialized;
  FilterResult r = FilterResult::kApplied;
  if (!p.allFinite()) r = FilterResult::kRejectedNotFinite;
  else if (!CovarianceOk(cov)) r = FilterResult::kRejectedBadCovariance;
  if (r == FilterResult::kApplied) {
    FilterEvent e;
    e.time = time;
    e.data = PositionEvent{p, cov};
    r = Submit(e);
  }
  Count(r, true);
  return r;
}

FrameSwitchResult LocalReferenceFilter::RequestFrameSwitch() {
  FrameSwitchResult out;
  if (!initialized_) return out;
  out.time = state_.time;
  out.old_frame_id = frame_id_;
  out.transform = SwitchFrame(state_, T_imu_body_, scratch_a_, scratch_b_);
  ++frame_id_;
  out.new_frame_id = frame_id_;
  out.result = FilterResult::kApplied;
  ++counters_.frame_switches;
  ResetReplayWindow(imu_end_);
  return out;
}

FilterOutput LocalReferenceFilter::Output() const {
  FilterOutput o;
  o.initialized = initialized_;
  o.time = state_.time;
  o.frame_id = frame_id_;
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = state_.q.toRotationMatrix();
  T.translation() = state_.p;
  o.T_frame_body = T * T_imu_body_;
  o.v_frame_imu = state_.v;
  o.accel_bias = state_.ba;
  o.gyro_bias = state_.bg;
  o.covariance = state_.P.topLeftCorner<9, 9>();
  return o;
}

bool LocalReferenceFilter::PoseAt(Timestamp time, PoseSample* out) const {
  if (!initialized_ || history_end_ == 0) return false;
  const uint64_t cap = history_.size();
  const uint64_t first = std::max(history_begin_, history_end_ > cap ? history_end_ - cap : 0);
  auto at = [&](uint64_t s) -> const PoseSample& { return history_[s % cap]; };
  if (time < at(first).time || time > at(history_end_ - 1).time) return false;
  uint64_t lo = first, hi = history_end_ - 1;  // find the first entry with time >= `time`
  while (lo < hi) {
    const uint64_t mid = lo + (hi - lo) / 2;
    if (at(mid).time < time) lo = mid + 1; else hi = mid;
  }
  const PoseSample& b = at(lo);
  if (b.time == time || lo == first) {
    *out = b;
    return true;
  }
  const PoseSample& a = at(lo - 1);
  if (a.frame_id != b.frame_id) {
    *out = (time - a.time) < (b.time - time) ? a : b;
    return true;
  }
  const double u = (time - a.time).seconds() / (b.time - a.time).seconds();
  *out = u < 0.5 ? a : b;
  out->time = time;
  const Eigen::Quaterniond qa(a.T_frame_body.linear()), qb(b.T_frame_body.linear());
  out->T_frame_body.linear() = qa.slerp(u, qb).toRotationMatrix();
  out->T_frame_body.translation() =
      (1.0 - u) * a.T_frame_body.translation() + u * b.T_frame_body.translation();
  return true;
}

}  // namespace cairn
