#pragma once
// The daemon's data path: the SensorSink that every source publishes into, the bounded queues,
// and the stage loops running on their executors. In live operation a publisher never waits (a
// full queue drops and counts); in deterministic replay every sample is consumed by its stage
// before the publisher returns, so a run's results do not depend on thread timing.

#include <array>
#include <atomic>
#include <functional>
#include <limits>
#include <map>
#include <memory>
#include <mutex>
#include <set>
#include <string>
#include <vector>

#include "daemon/pipeline/estimation_input_merge.h"
#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/executor.h"
#include "daemon/pipeline/executor_options.h"
#include "daemon/pipeline/graph_stage.h"
#include "daemon/pipeline/latency_histogram.h"
#include "daemon/pipeline/mapping_stage.h"
#include "daemon/pipeline/queued.h"
#include "daemon/pipeline/robot_detection_stage.h"
#include "daemon/pipeline/sensor_stream_stats.h"
#include "daemon/pipeline/spsc_queue.h"
#include "daemon/pipeline/stereo_rectify_stage.h"
#include "daemon/pipeline/structure_landmark_stage.h"
#include "daemon/pipeline/submap_matching_stage.h"
#include "daemon/pipeline/team_link.h"
#include "daemon/pipeline/telemetry_stage.h"
#include "daemon/pipeline/vo_stage.h"
#include "daemon/telemetry/graph_scene_encoder.h"
#include "estimation/graph/graph_worker.h"
#include "hal/calibration.h"
#include "hal/sensor_sink.h"
#include "mapping/frame_switch_requester_interface.h"

namespace cairn {

struct PipelineRates {
  double imu_hz = 0.0;      // nominal rates for gap detection; 0 disables it
  double camera_hz = 0.0;
  double wheel_hz = 0.0;
};

struct QueueReport {
  std::string name;
  size_t capacity = 0;
  uint64_t pushed = 0;
  uint64_t dropped = 0;
  uint64_t high_water = 0;
};

struct FaultReport {
  std::map<std::string, std::map<std::string, uint64_t>> counts;  // device -> kind -> count
  uint64_t total = 0;
  std::vector<std::string> first_messages;                         // the first few, verbatim
};

// Time from publication to consumption by the stage, on the monotonic wall clock
// ("imu_to_estimate": from publication of an IMU sample to the filter's estimate at it).
struct LatencyReport {
  std::string name;
  uint64_t count = 0;
  double p50 = 0.0, p99 = 0.0, p999 = 0.0, max = 0.0;  // s
  uint64_t over_1ms = 0;
};

struct StereoStageReport {
  uint64_t frame_counter_gaps = 0;  // frames the device numbered but we never saw
  int width = 0;
  int height = 0;
  uint64_t size_changes = 0;
};

// What the estimation chain (rectification -> visual odometry -> local reference filter) needs.
struct EstimationSetup {
  ImuCalibration imu;
  StereoCalibration stereo;
  WheelCalibration wheels;
  FilterOptions filter;
  VoOptions vo;
  FrameSwitchOptions frame_switch;
};

// Per-stage processing time of the estimation chain (host dependent: diagnostics only).
struct StageTimingReport {
  std::string name;
  uint64_t count = 0;
  double p50 = 0.0, p99 = 0.0, max = 0.0;  // s
};

class Pipeline final : public SensorSink, public FrameSwitchRequesterInterface {
 public:
  Pipeline(const ExecutorsOptions& executors, const QueueOptions& queues, PipelineRates rates,
           bool deterministic);
  ~Pipeline() override;

  // Hands every consumed sample on to `telemetry` (which must outlive the pipeline's threads).
  // Call before Start().
  void SetTelemetry(TelemetryStage* telemetry);
  // Runs the estimation chain on the data: stereo pairs are rectified (stereo executor), matched
  // by the keyframe visual odometry (vo executor) and fused with IMU and wheel data by the local
  // reference filter (estimation executor). Call before Start(). Without it the stages only
  // collect statistics.
  Status EnableEstimation(const EstimationSetup& setup);
  // Runs dense stereo and local mapping on every `every_nth_frame`-th rectified pair (mapping
  // executor; the camera is the rectified one of EnableEstimation), with the filter's estimates; mapping's submap partitioning then requests the frame
  // switches. Needs EnableEstimation() first (the setup's frame_switch policy must be off); call
  // before Start().
  Status EnableMapping(const MappingSetup& setup);
  // Builds and optimizes the robot's SLAM graph from the filter's estimates and frame switches
  // (graph executor). Needs EnableEstimation() first; call before Start().
  Status EnableGraph(const GraphStageOptions& options);
  // Matches finished submaps on the matcher pool and adds the matches to the graph (thesis 6.1).
  // Needs EnableMapping() and EnableGraph() first; call before Start().
  Status EnableMatching(const SubmapMatchingOptions& options, const std::string& robot);
  // Detects teammates' and landmarks' tags on every `every_nth_frame`-th left rectified image
  // (detection executor) and adds the sightings to the graph as factors d and o (and to the team).
  // `error_table_path` and `region_error_table_path` are options.error_table and
  // options.region_error_table resolved ("" for none). Needs EnableGraph() first; call before Start().
  Status EnableDetection(const RobotDetectionOptions& options, TagCarrierTable table, const std::string& robot,
                         const std::string& error_table_path, const std::string& region_error_table_path = "");
  // Shares this robot's frame switches, estimates, submaps and matches with the team through `team`
  // and takes teammates' items into the graph and the matcher (graph thread). Needs EnableGraph()
  // first; `team` must outlive the pipeline's threads. Call before Start().
  // `names`: every robot's name by graph letter.
  Status SetTeamLink(TeamLink* team, std::map<char, std::string> names);
  // Asks the filter to switch its frame of reference. One producer: the vo thread (the interim
  // distance/sigma policy) or, with mapping enabled, the mapping thread through the
  // FrameSwitchRequesterInterface below.
  void RequestFilterSwitch(const FilterSwitchRequest& request);
  // Submap partitioning's request (mapping thread).
  void RequestFrameSwitch(const FrameSwitchRequest& request) override;
  // Starts the stage threads.
  void Start();
  // Lets the stages consume what is queued, then joins them. Publishing must have stopped. With a
  // team, the exchange goes on until the team holds the same logs, for at most the team's linger
  // and `max_linger` seconds, and ends early when `cut_linger` (polled) says so.
  void StopAndDrain(double max_linger = std::numeric_limits<double>::infinity(),
                    const std::function<bool()>& cut_linger = nullptr);
  // How the team's linger at the end of the run went: "settled", "time" (its limit passed),
  // "cut" (cut_linger), or "" (no team).
  struct LingerReport {
    double seconds = 0.0;
    std::string ended;
  };
  LingerReport linger() const { return linger_; }

  void OnImu(const ImuSample& sample) override;
  void OnStereo(const StereoFrame& frame) override;
  void OnWheelOdometry(const WheelOdometrySample& sample) override;
  void OnTrigger(const TriggerEvent& event) override;
  void OnGnss(const GnssFix& fix) override;
  void OnDeviceFault(const DeviceFault& fault) override;

  // Valid after StopAndDrain().
  const SensorStreamStats& imu_stats() const { return imu_stats_; }
  const SensorStreamStats& stereo_stats() const { return stereo_stats_; }
  const SensorStreamStats& wheel_stats() const { return wheel_stats_; }
  const SensorStreamStats& trigger_stats() const { return trigger_stats_; }
  const StereoStageReport& stereo_report() const { return stereo_report_; }
  std::vector<QueueReport> queue_reports() const;
  std::vector<ExecutorReport> executor_reports() const;
  std::vector<LatencyReport> latency_reports() const;
  std::vector<StageTimingReport> stage_timing_reports() const;
  bool estimation_enabled() const { return estimation_ != nullptr; }
  // Valid after StopAndDrain() when estimation is enabled.
  EstimationReport estimation_report() const;
  const VoStageReport* vo_report() const { return vo_stage_ ? &vo_stage_->report() : nullptr; }
  const Trajectory* trajectory() const { return vo_stage_ ? &vo_stage_->trajectory() : nullptr; }
  const Trajectory* odometry() const { return vo_stage_ ? &vo_stage_->odometry() : nullptr; }
  uint64_t rectify_failures() const { return rectify_failures_; }
  bool mapping_enabled() const { return mapping_ != nullptr; }
  // Valid after StopAndDrain() when mapping is enabled.
  MappingStageReport mapping_report() const;
  std::map<uint64_t, Timestamp> submap_origin_times() const {
    return mapping_ ? mapping_->origin_times() : std::map<uint64_t, Timestamp>{};
  }
  // Valid after StopAndDrain(); null when the graph is not enabled.
  const GraphStage* graph() const { return graph_.get(); }
  // Teammates' finished submaps received, by graph letter and frame (valid after StopAndDrain()).
  const std::map<char, std::map<uint64_t, std::shared_ptr<const Submap>>>& team_submaps() const {
    return team_submaps_;
  }
  // Valid after StopAndDrain(); null when detection is not enabled.
  const RobotDetectionStage* detection() const { return detection_.get(); }
  // Valid after StopAndDrain(); null when matching is not enabled.
  const SubmapMatchingStage* matching() const { return matching_.get(); }
  // Valid after StopAndDrain(); null when plane landmarks are not enabled.
  const PlaneLandmarkStage* plane_landmarks() const { return planes_.get(); }
  const LineLandmarkStage* line_landmarks() const { return lines_.get(); }
  FaultReport fault_report() const;

  // Live progress (any thread).
  uint64_t consumed_imu() const { return imu_queue_.popped(); }
  uint64_t consumed_stereo() const { return stereo_queue_.popped(); }
  uint64_t total_dropped() const;
  // IMU samples the estimation thread consumed later than one IMU period after publication.
  uint64_t deadline_misses() const { return deadline_misses_.load(std::memory_order_relaxed); }

 private:
  template <class T>
  void Publish(SpscQueue<Queued<T>>& queue, const T& item, WorkSignal& signal);
  void EstimationLoop(std::stop_token stop);
  void StereoLoop(std::stop_token stop);
  void VoLoop(std::stop_token stop);
  void MappingLoop(std::stop_token stop);
  void DetectionLoop(std::stop_token stop);
  // Graph thread: this robot's sightings up to (not including) `before` into the graph and the team.
  void TakeSightings(Timestamp before);
  // Gives the graph the GNSS fixes measured before `before`.
  void TakeGnssFixes(Timestamp before);
  // Graph thread: where the graph places this robot and the carriers, for the detection thread.
  void PublishPredictions();
  void GraphLoop(std::stop_token stop);
  void DrainEstimates();
  void TakeMappingInputs();
  // Graph thread: finished submaps up to `max_id` into the matching stage and to the team.
  void TakeSubmaps(uint64_t max_id);
  // Graph thread (or the stopping thread once it is joined): teammates' items into the graph.
  bool TakeTeamInputs();
  void PublishToTeam(const GraphInput& input);

  const bool deterministic_;
  WorkSignal estimation_signal_;
  WorkSignal stereo_signal_;
  WorkSignal consumed_signal_;  // deterministic mode: the publisher waits on this
  SpscQueue<Queued<ImuSample>> imu_queue_;
  SpscQueue<Queued<WheelOdometrySample>> wheel_queue_;
  SpscQueue<Queued<TriggerEvent>> trigger_queue_;
  SpscQueue<Queued<StereoFrame>> stereo_queue_;
  // Estimation chain: stereo -> vo (rectified pairs), stereo -> estimation (clone at exposure),
  // vo -> estimation (delta poses, frame-switch requests), estimation -> vo (estimates).
  WorkSignal vo_signal_;
  SpscQueue<Queued<RectifiedPair>> rectified_queue_;
  SpscQueue<Queued<Timestamp>> clone_queue_;
  SpscQueue<Queued<VoResult>> vo_result_queue_;
  SpscQueue<Queued<FilterSwitchRequest>> switch_queue_;
  SpscQueue<FrameEstimate> estimate_queue_;
  EstimationInputMerge estimation_inputs_;
  // Mapping: stereo -> mapping (every Nth rectified pair), estimation -> mapping (estimates and the
  // switches made), mapping -> estimation (partitioning's requests, through switch_queue_).
  WorkSignal mapping_signal_;
  SpscQueue<Queued<RectifiedPair>> dense_queue_;
  SpscQueue<FrameEstimate> mapping_estimate_queue_;
  SpscQueue<FrameSwitchEvent> switch_event_queue_;
  uint64_t mapping_estimates_seen_ = 0;  // estimation thread: when to wake the mapping thread
  // Graph: estimation -> graph (valid estimates and switches, in one queue to keep their order).
  WorkSignal graph_signal_;
  SpscQueue<GraphInput> graph_queue_;
  uint64_t graph_inputs_seen_ = 0;  // estimation thread: when to wake the graph thread
  // Matching: mapping -> graph thread (finished submaps).
  SpscQueue<std::shared_ptr<const Submap>> submap_queue_;
  // Detection: stereo -> detection (every Nth rectified pair), detection -> graph (sightings).
  WorkSignal detection_signal_;
  SpscQueue<Queued<RectifiedPair>> detection_queue_;
  SpscQueue<TagSighting> sighting_queue_;
  // GNSS: the receiver's (or simulator's) thread -> graph thread. `after`: the latest IMU time
  // published before the fix, so that a deterministic run takes each fix at the same estimate.
  struct QueuedFix {
    GnssFix fix;
    Timestamp after;
  };
  SpscQueue<QueuedFix> gnss_queue_;
  bool gnss_enabled_ = false;
  std::atomic<int64_t> last_imu_ns_{INT64_MIN};
  const Duration imu_deadline_;
  std::atomic<uint64_t> deadline_misses_{0};

  Executor estimation_exec_;
  Executor stereo_;
  Executor vo_;
  Executor mapping_exec_;
  Executor graph_exec_;
  GraphWorker graph_worker_{false};  // runs on graph_full_solve_exec_
  Executor graph_full_solve_exec_;
  ExecutorOptions matcher_options_;  // the matcher pool's workers
  Executor detection_exec_;

  // Owned by the estimation thread until joined.
  SensorStreamStats imu_stats_;
  SensorStreamStats wheel_stats_;
  SensorStreamStats trigger_stats_;
  LatencyHistogram imu_latency_, wheel_latency_;
  LatencyHistogram imu_to_estimate_;  // IMU sample published -> filter propagated to it
  // Owned by the stereo thread until joined.
  LatencyHistogram stereo_latency_;
  SensorStreamStats stereo_stats_;
  StereoStageReport stereo_report_;
  uint64_t last_frame_counter_ = 0;

  // Estimation chain (null when not enabled); each is used by one thread until joined.
  std::unique_ptr<EstimationStage> estimation_;
  std::unique_ptr<StereoRectifyStage> rectify_;
  std::unique_ptr<VoStage> vo_stage_;
  LatencyHistogram rectify_time_;
  uint64_t rectify_failures_ = 0;
  int pending_dropped_ = 0;
  std::unique_ptr<MappingStage> mapping_;
  std::unique_ptr<GraphStage> graph_;
  std::unique_ptr<SubmapMatchingStage> matching_;
  std::unique_ptr<PlaneLandmarkStage> planes_;
  std::unique_ptr<LineLandmarkStage> lines_;
  // The submaps' comparisons (matcher, plane landmarks) at a fixed point of the graph's input.
  void StepSubmapWork();
  std::unique_ptr<RobotDetectionStage> detection_;
  int64_t detection_every_ = 1;
  uint64_t detection_counter_ = 0;  // stereo thread
  std::map<std::string, char> letters_;  // team names -> graph letters
  // The graph's places of the tag carriers (live runs): the graph thread fills the scratch and
  // copies it under the mutex, the detection thread copies it out before each image.
  bool predict_carriers_ = false;
  std::vector<std::string> robot_carriers_, landmark_carriers_;  // other robots; landmarks by index
  CarrierPredictions predictions_scratch_;  // graph thread
  Timestamp carriers_placed_time_;          // graph thread: data time of the last teammates' refresh
  std::mutex predictions_mutex_;
  CarrierPredictions predictions_;
  GraphSceneEncoder graph_scene_;       // graph thread: the live /graph view
  uint64_t graph_shown_origins_ = 0;
  Timestamp graph_shown_time_;
  int64_t dense_every_ = 1;
  uint64_t dense_counter_ = 0;  // stereo thread
  uint64_t mapping_switch_requests_ = 0;  // mapping thread
  std::atomic<bool> filter_running_{false};

  TelemetryStage* telemetry_ = nullptr;
  TeamLink* team_ = nullptr;
  std::map<char, std::map<uint64_t, std::shared_ptr<const Submap>>> team_submaps_;  // graph thread
  std::set<std::pair<char, uint64_t>> team_submaps_shown_;                          // graph thread
  void ShowTeamSubmaps();
  mutable std::mutex fault_mutex_;
  FaultReport faults_;
  bool started_ = false;
  LingerReport linger_;
};

}  // namespace cairn
