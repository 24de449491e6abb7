#pragma once
// Local reference filter (thesis 4.1): a hard-real-time error-state EKF on IMU data with pose
// clones at camera triggers, delayed relative-pose updates between clones, wheel-odometry
// velocity updates and frame-of-reference switches.
//
// One thread drives it. All memory is allocated by the constructor; afterwards no call allocates,
// locks or does I/O, and the work per call is bounded by the configured capacities.
//
// Delayed measurements are exact: every input is kept in time order in an IMU ring and an event
// log, and the filter state is saved right after each clone (the time a relative-pose measurement
// refers to; a replay saves again only the first clone it passes, where the next late measurement
// starts). A measurement whose time is already past restores the newest saved state before it,
// applies the measurement in its place and re-propagates the buffered IMU data to the present.
// The result equals in-order processing; the IMU-rate output is never held back, it is corrected
// when the late measurement arrives. Replays are bounded by max_update_delay.
//
// A frame switch is a barrier: measurements older than the newest switch are applied at the
// switch (relative poses) or rejected (clones, wheel, position) instead of being replayed across
// it, so the transform handed to the SLAM graph is never revised.

#include <cstdint>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/timestamp.h"
#include "estimation/filter/filter_event.h"
#include "estimation/filter/filter_event_log.h"
#include "estimation/filter/filter_options.h"
#include "estimation/filter/filter_result.h"
#include "estimation/filter/filter_state.h"
#include "estimation/filter/frame_switch.h"
#include "estimation/filter/imu_propagator.h"
#include "estimation/filter/static_initializer.h"
#include "hal/calibration.h"
#include "hal/imu_sample.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

struct FilterCounters {
  uint64_t imu_accepted = 0;
  uint64_t imu_not_finite = 0;
  uint64_t imu_out_of_order = 0;
  uint64_t imu_duplicate = 0;
  uint64_t imu_far_future = 0;
  uint64_t imu_resyncs = 0;
  uint64_t clones_requested = 0;
  uint64_t clones_marginalized = 0;
  uint64_t updates_applied = 0;     // relative pose, wheel and position updates
  uint64_t updates_direct = 0;      // relative poses applied at the present (beyond replay window)
  uint64_t updates_rejected = 0;
  uint64_t events_rejected = 0;     // clones, releases and measurements refused on arrival
  uint64_t replays = 0;
  uint64_t replayed_imu_samples = 0;
  uint64_t frame_switches = 0;
};

struct CloneRequest {
  FilterResult result = FilterResult::kNotInitialized;
  CloneId id = kNoClone;
};

// Body-frame x/y velocity of the body origin (wheel odometry), with covariance.
struct BodyVelocity {
  Timestamp time;
  Eigen::Vector2d v_xy = Eigen::Vector2d::Zero();
  Eigen::Matrix2d covariance = Eigen::Matrix2d::Identity();
};

// Estimate at one instant in the local frame `frame_id`. Covariance of the IMU error state
// [position, velocity, attitude (right perturbation)].
struct FilterOutput {
  bool initialized = false;
  Timestamp time;
  uint64_t frame_id = 0;
  Eigen::Isometry3d T_frame_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d v_frame_imu = Eigen::Vector3d::Zero();
  Eigen::Vector3d accel_bias = Eigen::Vector3d::Zero();
  Eigen::Vector3d gyro_bias = Eigen::Vector3d::Zero();
  Eigen::Matrix<double, 9, 9> covariance = Eigen::Matrix<double, 9, 9>::Zero();
};

struct PoseSample {
  Timestamp time;
  uint64_t frame_id = 0;
  Eigen::Isometry3d T_frame_body = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Zero();  // [position; attitude] of the IMU
};

struct FrameSwitchResult {
  FilterResult result = FilterResult::kNotInitialized;
  Timestamp time;
  uint64_t old_frame_id = 0;
  uint64_t new_frame_id = 0;
  FrameTransform transform;
};

class LocalReferenceFilter {
 public:
  // Clones whose core-clone cross-covariance is propagated with every IMU sample instead of being
  // deferred (the clones made since the last relative-pose update); more are folded back first.
  static constexpr int kMaxCurrentCrossBlocks = 6;

  LocalReferenceFilter(const FilterOptions& options, const ImuCalibration& imu,
                       const WheelCalibration& wheels = WheelCalibration{});

  // Starts the filter from a known state (else the first still window initializes it). The
  // covariance is the 15x15 core block.
  void Initialize(Timestamp time, const Eigen::Vector3d& p, const Eigen::Vector3d& v,
                  const Eigen::Quaterniond& q_frame_imu, const Eigen::Vector3d& ba,
                  const Eigen::Vector3d& bg, const Eigen::Matrix<double, 15, 15>& covariance,
                  const ImuSample& first_sample);

  FilterResult Propagate(const ImuSample& sample);
  // A pose clone at the exposure time of a camera trigger (interpolated between IMU samples).
  CloneRequest Clone(Timestamp trigger_time);
  // Marks a clone as no longer referenced: it is marginalized.
  FilterResult ReleaseClone(CloneId id);
  // Delta pose T_kf_cur of the body between two clones with covariance of
  // [translation; rotation (right perturbation)] in the keyframe body frame.
  FilterResult ApplyRelativePose(CloneId keyframe, CloneId current, const Eigen::Isometry3d& T_kf_cur,
                                 const Matrix6d& covariance);
  FilterResult ApplyWheelOdometry(const BodyVelocity& velocity);
  // Per-wheel speeds and steering angles (hal), turned into a body velocity with the wheel
  // calibration given at construction (estimation/filter/wheel_velocity.h).
  FilterResult ApplyWheelOdometry(const WheelOdometrySample& sample);
  // IMU position in the current local frame (external positioning, tests).
  FilterResult ApplyPosition(Timestamp time, const Eigen::Vector3d& p, const Eigen::Matrix3d& cov);
  // Switches to a new local frame at the body's current position and yaw, now.
  FrameSwitchResult RequestFrameSwitch();

  FilterOutput Output() const;
  // The estimate at `time`, interpolated in the IMU-rate history; false when outside it.
  bool PoseAt(Timestamp time, PoseSample* out) const;

  bool initialized() const { return initialized_; }
  const FilterState& state() const { return state_; }
  const FilterCounters& counters() const { return counters_; }
  uint64_t frame_id() const { return frame_id_; }
  int active_clones() const;

 private:
  // The state right after a clone. P is kept packed (its current parts only): a replay writes
  // one snapshot per clone it passes and restores one, and the full matrix is 60 KB.
  struct Snapshot {
    FilterStateHead head;
    PackedCovariance P{};
    uint64_t imu_seq = 0;    // first IMU sample not yet fully integrated
    uint64_t event_seq = 0;  // first event not yet processed
  };

  const ImuSample& ImuAt(uint64_t seq) const { return imu_[seq % imu_.size()]; }
  FilterResult Submit(FilterEvent e);
  void ProcessNow(const FilterEvent& e);
  void Step(uint64_t k);
  FilterResult ProcessEvent(const FilterEvent& e);
  void AddClone(CloneId id);
  void Marginalize(int slot);
  int SlotOf(CloneId id) const;
  void PushSnapshot(uint64_t imu_seq);
  void ResetReplayWindow(uint64_t imu_seq);
  void WriteHistory(uint64_t k);
  void Count(FilterResult r, bool measurement);

  FilterOptions options_;
  ImuCalibration calibration_;
  WheelCalibration wheels_;
  Eigen::Isometry3d T_imu_body_;  // inverse of calibration_.T_body_imu, computed once
  ImuPropagator propagator_;
  StaticInitializer initializer_;
  FilterState state_;
  bool initialized_ = false;
  uint64_t frame_id_ = 0;
  CloneId next_clone_id_ = 1;
  FilterCounters counters_;

  // Rings addressed by ever-increasing sequence numbers.
  std::vector<ImuSample> imu_;
  uint64_t imu_begin_ = 0, imu_end_ = 0;
  bool have_last_imu_ = false;
  Timestamp last_imu_time_;
  int64_t far_future_run_ = 0;
  Timestamp far_future_last_;
  FilterEventLog events_;
  std::vector<Snapshot> snapshots_;
  uint64_t snap_begin_ = 0, snap_end_ = 0;
  std::vector<PoseSample> history_;
  uint64_t history_begin_ = 0, history_end_ = 0;
  uint64_t current_imu_seq_ = 0;  // snapshot position for an event processed now
  bool replaying_ = false;
  bool replay_saved_ = false;  // the running replay has saved the state at a clone

  StateCovariance scratch_a_, scratch_b_;
};

}  // namespace cairn
