#pragma once
// The telemetry executor: what the stages consumed is encoded once and goes to the MCAP recorder
// and to the live Foxglove stream (each optional). Stages hand samples over through bounded
// queues (allocation and lock free, so the estimation thread may call it); each item carries a
// global sequence number so recordings keep the order in which the pipeline consumed samples.
// Live: a full queue drops and counts. Deterministic replay: the stage waits instead.

#include <atomic>
#include <memory>
#include <string>

#include "daemon/pipeline/executor.h"
#include "daemon/pipeline/spsc_queue.h"
#include "daemon/telemetry/estimate_encoder.h"
#include "daemon/telemetry/foxglove_server.h"
#include "daemon/telemetry/live_stream_options.h"
#include "daemon/telemetry/mcap_recorder.h"
#include "daemon/telemetry/sample_encoder.h"
#include "mapping/submap.h"

namespace cairn {

struct LiveStreamReport {
  uint16_t port = 0;
  uint64_t published = 0;
  uint64_t dropped = 0;       // oldest messages dropped for slow clients
  uint64_t protocol_errors = 0;
  double server_cpu_seconds = 0.0;  // the WebSocket thread, after the stream stopped
};

class TelemetryStage {
 public:
  TelemetryStage(const ExecutorOptions& executor, size_t queue_depth, bool deterministic);
  ~TelemetryStage();

  // `calibration`: the encoded sensor calibration each recording file starts with (empty: none known).
  void EnableRecording(std::string directory, const RecordingOptions& options, std::string calibration = {});
  Status EnableLiveStream(const std::string& robot_name, const LiveStreamOptions& options);

  void Start();
  // Handles everything queued, closes the recording and the stream, joins the thread.
  void StopAndDrain();

  void OfferImu(const ImuSample& s);
  void OfferWheelOdometry(const WheelOdometrySample& s);
  void OfferStereo(const StereoFrame& f);
  // The filter's body pose at a camera frame, in the robot's first local frame (one producer: the
  // odometry thread, or the main thread once it has stopped).
  void OfferPose(Timestamp time, const Eigen::Isometry3d& T_map_body);
  // A finished submap placed in the first local frame, or a snapshot of the rolling obstacle map
  // (one producer: the mapping thread, or the main thread once it has stopped).
  void OfferSubmap(Timestamp time, std::shared_ptr<const Submap> submap, const Eigen::Isometry3d& T_map_submap);
  void OfferObstacleGrid(Timestamp time, std::shared_ptr<const GridMap> grid, const Eigen::Isometry3d& T_map_local,
                         double z);
  // The daemon's periodic status line, to the live /diagnostics channel (any thread).
  void PublishDiagnostics(const std::string& status);
  // Live-only channels: /graph (foxglove.SceneUpdate, the latest one kept for late viewers) and
  // /log (foxglove.Log, every log line from the stream's start, the last 200 kept). Recordings
  // leave them out: a replay of a recording rebuilds the graph, and log lines carry wall time.
  bool live() const { return live_ != nullptr; }
  void PublishGraph(Timestamp time, const std::string& encoded);

  bool recording() const { return recorder_ != nullptr; }
  const RecordingReport& recording_report() const { return recorder_->report(); }
  LiveStreamReport live_report() const;
  // Images the PNG/JPEG encoder refused (not recorded or streamed); valid after StopAndDrain().
  uint64_t image_codec_failures() const { return image_codec_failures_; }
  uint64_t dropped() const {
    return imu_.dropped() + wheel_.dropped() + stereo_.dropped() + poses_.dropped() + maps_.dropped();
  }
  ExecutorReport executor_report() const { return executor_.report(); }

 private:
  template <class T>
  struct Item {
    uint64_t sequence = 0;
    T value{};
  };
  struct PoseItem {
    Timestamp time;
    Eigen::Isometry3d T_map_body = Eigen::Isometry3d::Identity();
  };
  struct MapItem {
    Timestamp time;
    std::shared_ptr<const Submap> submap;  // or
    std::shared_ptr<const GridMap> grid;
    Eigen::Isometry3d T_map_frame = Eigen::Isometry3d::Identity();
    double z = 0.0;
  };
  template <class T>
  void Offer(SpscQueue<Item<T>>& queue, const T& value);
  void HandleMap(const MapItem& m);
  void DetachLog();
  bool Wanted(TelemetryTopic topic) const;
  void Loop(std::stop_token stop);
  void Emit(TelemetryTopic topic, Timestamp time, const std::string& encoded);
  void HandleStereo(const StereoFrame& f);
  // The encoded message (valid until the next encoding), or null when the codec failed.
  const std::string* EncodeImage(const Image& image, Timestamp time, const char* frame,
                                 const ImageEncodingOptions& options);

  const bool deterministic_;
  std::atomic<uint64_t> next_sequence_{0};
  WorkSignal work_;
  WorkSignal space_;
  SpscQueue<Item<ImuSample>> imu_;
  SpscQueue<Item<WheelOdometrySample>> wheel_;
  SpscQueue<Item<StereoFrame>> stereo_;
  SpscQueue<Item<PoseItem>> poses_;
  SpscQueue<Item<MapItem>> maps_;
  SampleEncoder encoder_;
  EstimateEncoder estimates_;
  std::unique_ptr<McapRecorder> recorder_;
  std::unique_ptr<FoxgloveServer> live_;
  uint32_t live_channel_[kTelemetryTopicCount] = {};
  uint32_t diagnostics_channel_ = 0;
  uint32_t graph_channel_ = 0;
  uint32_t log_channel_ = 0;
  std::shared_ptr<class LiveLogSink> log_sink_;
  int64_t image_every_ = 1;
  ImageEncodingOptions recording_images_;
  ImageEncodingOptions live_images_;
  uint64_t image_codec_failures_ = 0;
  uint64_t stereo_seen_ = 0;
  std::atomic<uint64_t> live_published_{0};
  Executor executor_;
  bool started_ = false;
  bool error_logged_ = false;
};

}  // namespace cairn
