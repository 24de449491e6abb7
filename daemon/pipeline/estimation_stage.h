#pragma once
// What the hard-real-time estimation thread does with its inputs: the local reference filter on
// IMU (and wheel) data, a pose clone per stereo frame at its exposure time, the visual-odometry
// delta poses between the clones of a keyframe and a frame, clone releases, and frame switches
// on request. Per camera frame it emits the filter's estimate at the frame's time (once the
// filter has reached it and the frame's odometry result is in), chained through all frame
// switches into the first frame. All memory is allocated by the constructor.

#include <array>
#include <cstdint>
#include <memory>

#include <Eigen/Geometry>

#include "daemon/pipeline/spsc_queue.h"
#include "estimation/filter/local_reference_filter.h"
#include "estimation/vo/frame_switch_policy.h"
#include "estimation/vo/keyframe_visual_odometry.h"

namespace cairn {

// The filter's estimate at one camera frame, and feedback for the odometry.
struct FrameEstimate {
  Timestamp time;
  bool valid = false;          // the filter was initialized and covers the time
  uint64_t frame_id = 0;       // local frame of T_frame_body
  Eigen::Isometry3d T_frame_body = Eigen::Isometry3d::Identity();
  Eigen::Isometry3d T_first_body = Eigen::Isometry3d::Identity();  // chained through switches
  double position_sigma = 0.0;  // m, largest standard deviation of the position
  Eigen::Matrix3d position_covariance = Eigen::Matrix3d::Zero();  // m^2, in the local frame
  Matrix6d pose_covariance = Matrix6d::Zero();  // [position; attitude (right perturbation)] of the IMU
  VoStatus vo_status = VoStatus::kNoKeyframe;
  // The keyframe the odometry used has no clone in the filter (filter not yet initialized, or the
  // clone is gone): the odometry must stop using it.
  bool keyframe_clone_missing = false;
  Timestamp keyframe_time;
};

// A frame switch asked of the filter (by the odometry's interim policy or by mapping's submap
// partitioning); the filter switches at its current time.
struct FilterSwitchRequest {
  Timestamp time;  // of the estimate that prompted it
  FrameSwitchReason reason = FrameSwitchReason::kNone;
};

// A frame switch the filter made: the new local frame (= new submap origin) in the old one, with
// its covariance, for mapping (rolling map, submap chain) and the SLAM graph (factor w).
struct FrameSwitchEvent {
  Timestamp time;
  uint64_t old_frame_id = 0;
  uint64_t new_frame_id = 0;
  FrameTransform transform;
};

// What the estimation thread hands the graph, in its order: a filter estimate or a frame switch.
struct GraphInput {
  enum class Kind : uint8_t { kEstimate, kFrameSwitch };
  Kind kind = Kind::kEstimate;
  FrameEstimate estimate;
  FrameSwitchEvent frame_switch;
};

struct EstimationReport {
  FilterCounters filter;
  uint64_t vo_results = 0;
  uint64_t vo_updates_applied = 0;
  uint64_t vo_updates_rejected = 0;  // refused by the filter (gate, covariance, unknown clone)
  uint64_t vo_missing_clone = 0;     // results whose keyframe or frame has no clone
  uint64_t clones_failed = 0;        // clone requests the filter refused (e.g. not initialized)
  uint64_t frame_switches = 0;
  std::array<uint64_t, 3> switch_reasons{};  // by FrameSwitchReason
  uint64_t estimates_emitted = 0;
  uint64_t estimates_dropped = 0;  // output queue full
  uint64_t mapping_estimates_dropped = 0;
  uint64_t switch_events_dropped = 0;
  uint64_t graph_inputs_dropped = 0;
  bool initialized = false;
};

class EstimationStage {
 public:
  EstimationStage(const FilterOptions& options, const ImuCalibration& imu, const WheelCalibration& wheels,
                  SpscQueue<FrameEstimate>* estimates);

  void OnImu(const ImuSample& s);
  void OnWheel(const WheelOdometrySample& s);
  void OnFrame(Timestamp time);  // a stereo exposure: clone
  void OnVoResult(const VoResult& r);
  void OnFrameSwitch(const FilterSwitchRequest& request);
  // Also hands every per-frame estimate to `estimates` and every switch the filter makes to
  // `switches` (the mapping stage); call before the thread starts.
  void AlsoPublishTo(SpscQueue<FrameEstimate>* estimates, SpscQueue<FrameSwitchEvent>* switches) {
    mapping_estimates_ = estimates;
    switch_events_ = switches;
  }
  // Valid estimates and the frame switches, in one queue so the graph sees them in their order.
  void PublishToGraph(SpscQueue<GraphInput>* inputs) { graph_inputs_ = inputs; }

  bool initialized() const { return filter_.initialized(); }
  EstimationReport report() const;

 private:
  struct CloneEntry {
    Timestamp time;
    CloneId id = kNoClone;
  };
  struct PendingFrame {
    Timestamp time;
    VoStatus status = VoStatus::kNoKeyframe;
    bool missing = false;
    Timestamp keyframe_time;
  };
  CloneId FindClone(Timestamp t) const;
  void Release(Timestamp t);
  void Emit(const PendingFrame& f);
  void FlushPending();

  LocalReferenceFilter filter_;
  SpscQueue<FrameEstimate>* estimates_;
  SpscQueue<FrameEstimate>* mapping_estimates_ = nullptr;
  SpscQueue<FrameSwitchEvent>* switch_events_ = nullptr;
  SpscQueue<GraphInput>* graph_inputs_ = nullptr;
  GraphInput graph_input_;  // scratch: the estimate is copied in, not built on the real-time stack
  std::array<CloneEntry, 64> clones_{};
  size_t next_clone_slot_ = 0;
  std::array<PendingFrame, 32> pending_{};
  size_t pending_begin_ = 0, pending_end_ = 0;
  // T_first_frame of the last local frames (indexed by frame id modulo the size).
  std::array<Eigen::Isometry3d, 64> T_first_frame_{};
  EstimationReport report_;
};

}  // namespace cairn
