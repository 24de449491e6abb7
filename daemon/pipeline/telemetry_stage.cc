#include "daemon/pipeline/telemetry_stage.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <limits>

#include "common/json_writer.h"
#include "common/monotonic_clock.h"
#include "daemon/telemetry/live_log_sink.h"
#include "daemon/telemetry/protobuf_schema.h"
#include "foxglove/Log.pb.h"
#include "foxglove/SceneUpdate.pb.h"

namespace cairn {

TelemetryStage::TelemetryStage(const ExecutorOptions& executor, size_t queue_depth, bool deterministic)
    : deterministic_(deterministic),
      imu_(queue_depth * 8),  // IMU samples are small and frequent
      wheel_(queue_depth),
      stereo_(queue_depth),
      poses_(queue_depth),
      maps_(16),  // a few submaps and grids a minute; each holds its data by reference
      executor_("telemetry", executor) {}

TelemetryStage::~TelemetryStage() {
  StopAndDrain();
  DetachLog();  // also when the stage never started
}

void TelemetryStage::EnableRecording(std::string directory, const RecordingOptions& options, std::string calibration) {
  recorder_ = std::make_unique<McapRecorder>(std::move(directory), options);
  recorder_->SetCalibration(std::move(calibration));
  recording_images_ = options.images;
}

Status TelemetryStage::EnableLiveStream(const std::string& robot_name, const LiveStreamOptions& options) {
  live_ = std::make_unique<FoxgloveServer>("cairnd " + robot_name);
  const auto add = [this](const char* topic, const google::protobuf::Descriptor* d) {
    const std::string set = ProtobufFileDescriptorSet(d);
    return live_->AddChannel(FoxgloveChannel{0, topic, "protobuf", d->full_name(),
                                             FoxgloveServer::Base64({reinterpret_cast<const uint8_t*>(set.data()), set.size()}),
                                             "protobuf"});
  };
  for (int t = 0; t < kTelemetryTopicCount; ++t) {
    const auto topic = static_cast<TelemetryTopic>(t);
    live_channel_[t] = add(TelemetryTopicName(topic), TelemetryTopicDescriptor(topic));
  }
  diagnostics_channel_ = live_->AddChannel(FoxgloveChannel{
      0, "/diagnostics", "json", "cairn.Diagnostics",
      R"({"type":"object","properties":{"status":{"type":"string"},"time_ns":{"type":"integer"}}})",
      "jsonschema"});
  graph_channel_ = add("/graph", foxglove::SceneUpdate::descriptor());
  log_channel_ = add("/log", foxglove::Log::descriptor());
  live_->SetLatched(graph_channel_, 1);
  live_->SetLatched(log_channel_, 200);
  image_every_ = options.image_every;
  live_images_ = options.images;
  const Status s = live_->Start(options.address, static_cast<uint16_t>(options.port),
                                static_cast<size_t>(options.client_queue));
  if (!s.ok()) {
    live_.reset();
    return s;
  }
  // Only the main thread runs yet (stages and sources start later), so the logger's sink list may
  // change here; StopAndDrain() detaches it again once they have stopped.
  log_sink_ = std::make_shared<LiveLogSink>("cairnd " + robot_name, [this](Timestamp t, std::span<const uint8_t> b) {
    live_->Publish(log_channel_, t, b);
  });
  spdlog::default_logger_raw()->sinks().push_back(log_sink_);
  return s;
}

void TelemetryStage::Start() {
  if (started_) return;
  started_ = true;
  executor_.Start([this](std::stop_token stop) { Loop(stop); });
}

void TelemetryStage::StopAndDrain() {
  if (!started_) return;
  executor_.RequestStop();
  work_.Notify();
  executor_.Join();
  started_ = false;
  if (recorder_) {
    if (Status s = recorder_->Close(); !s.ok()) spdlog::error("recording: {}", s.ToString());
  }
  DetachLog();
  if (live_) live_->Stop();
}

void TelemetryStage::DetachLog() {
  if (!log_sink_) return;
  log_sink_->Detach();
  auto& sinks = spdlog::default_logger_raw()->sinks();
  sinks.erase(std::remove(sinks.begin(), sinks.end(), log_sink_), sinks.end());
  log_sink_.reset();
}

void TelemetryStage::PublishGraph(Timestamp time, const std::string& encoded) {
  if (live_) live_->Publish(graph_channel_, time, {reinterpret_cast<const uint8_t*>(encoded.data()), encoded.size()});
}

LiveStreamReport TelemetryStage::live_report() const {
  LiveStreamReport r;
  if (!live_) return r;
  r.port = live_->port();
  r.published = live_published_.load();
  r.dropped = live_->dropped_messages();
  r.protocol_errors = live_->protocol_errors();
  r.server_cpu_seconds = live_->cpu_seconds();
  return r;
}

template <class T>
void TelemetryStage::Offer(SpscQueue<Item<T>>& queue, const T& value) {
  const Item<T> item{next_sequence_.fetch_add(1, std::memory_order_relaxed), value};
  if (deterministic_) {
    while (true) {
      const uint32_t seen = space_.sequence();
      if (queue.size() < queue.capacity() && queue.TryPush(item)) break;
      space_.WaitChange(seen);
    }
  } else {
    queue.TryPush(item);
  }
  work_.Notify();
}

void TelemetryStage::PublishDiagnostics(const std::string& status) {
  if (!live_ || !live_->HasSubscribers(diagnostics_channel_)) return;
  const Timestamp now = MonotonicClock().Now();
  JsonWriter j(false);
  j.BeginObject().Field("status", status).Field("time_ns", now.nanoseconds()).EndObject();
  live_->Publish(diagnostics_channel_, now, {reinterpret_cast<const uint8_t*>(j.str().data()), j.str().size()});
}

void TelemetryStage::OfferImu(const ImuSample& s) { Offer(imu_, s); }
void TelemetryStage::OfferWheelOdometry(const WheelOdometrySample& s) { Offer(wheel_, s); }
void TelemetryStage::OfferStereo(const StereoFrame& f) { Offer(stereo_, f); }
void TelemetryStage::OfferPose(Timestamp time, const Eigen::Isometry3d& T_map_body) {
  Offer(poses_, PoseItem{time, T_map_body});
}
void TelemetryStage::OfferSubmap(Timestamp time, std::shared_ptr<const Submap> submap,
                                 const Eigen::Isometry3d& T_map_submap) {
  Offer(maps_, MapItem{time, std::move(submap), nullptr, T_map_submap, 0.0});
}
void TelemetryStage::OfferObstacleGrid(Timestamp time, std::shared_ptr<const GridMap> grid,
                                       const Eigen::Isometry3d& T_map_local, double z) {
  Offer(maps_, MapItem{time, nullptr, std::move(grid), T_map_local, z});
}

bool TelemetryStage::Wanted(TelemetryTopic topic) const {
  return recorder_ != nullptr || (live_ && live_->HasSubscribers(live_channel_[static_cast<int>(topic)]));
}

void TelemetryStage::HandleMap(const MapItem& m) {
  // Clouds and grids are large: encoded only for a recorder or a subscribed client.
  if (m.submap && Wanted(TelemetryTopic::kSubmapCloud)) {
    Emit(TelemetryTopic::kSubmapCloud, m.time, estimates_.Cloud(m.time, m.T_map_frame, m.submap->points()));
  }
  if (m.grid && Wanted(TelemetryTopic::kObstacleGrid)) {
    Emit(TelemetryTopic::kObstacleGrid, m.time, estimates_.Grid(m.time, m.T_map_frame, m.z, *m.grid));
  }
}

void TelemetryStage::Emit(TelemetryTopic topic, Timestamp time, const std::string& encoded) {
  if (recorder_) {
    const Status s = recorder_->Write(topic, time, encoded);
    if (!s.ok() && !error_logged_) {
      // A full disk must not stop the robot: log once, count the rest in the report.
      spdlog::error("recording: {} (further errors are only counted)", s.ToString());
      error_logged_ = true;
    }
  }
  if (live_) {
    const uint32_t channel = live_channel_[static_cast<int>(topic)];
    if (live_->HasSubscribers(channel)) {
      live_->Publish(channel, time, {reinterpret_cast<const uint8_t*>(encoded.data()), encoded.size()});
      live_published_.fetch_add(1, std::memory_order_relaxed);
    }
  }
}

const std::string* TelemetryStage::EncodeImage(const Image& image, Timestamp time, const char* frame,
                                               const ImageEncodingOptions& options) {
  if (options.format == ImageFormat::kRaw) return &encoder_.Image(image, time, frame);
  const std::string* encoded = nullptr;
  if (encoder_.Compressed(image, time, frame, options, &encoded)) return encoded;
  if (image_codec_failures_++ == 0) spdlog::error("telemetry: an image did not compress (further failures are only counted)");
  return nullptr;
}

void TelemetryStage::HandleStereo(const StereoFrame& f) {
  Emit(TelemetryTopic::kStereoInfo, f.time, encoder_.StereoInfo(f));
  const bool live_turn = live_ && stereo_seen_ % static_cast<uint64_t>(image_every_) == 0;
  ++stereo_seen_;
  const auto topic_of = [](bool left, ImageFormat format) {
    if (format == ImageFormat::kRaw) return left ? TelemetryTopic::kCam0Image : TelemetryTopic::kCam1Image;
    return left ? TelemetryTopic::kCam0Compressed : TelemetryTopic::kCam1Compressed;
  };
  for (const bool left : {true, false}) {
    const Image& image = left ? f.left : f.right;
    const char* frame = left ? "cam0" : "cam1";
    // Images are the expensive part: encode only for a recorder or a subscribed client, and once
    // when both want the same encoding.
    const std::string* recorded = nullptr;
    if (recorder_) {
      recorded = EncodeImage(image, f.time, frame, recording_images_);
      if (recorded != nullptr) {
        if (Status s = recorder_->Write(topic_of(left, recording_images_.format), f.time, *recorded);
            !s.ok() && !error_logged_) {
          spdlog::error("recording: {} (further errors are only counted)", s.ToString());
          error_logged_ = true;
        }
      }
    }
    if (!live_turn) continue;
    const uint32_t channel = live_channel_[static_cast<int>(topic_of(left, live_images_.format))];
    if (!live_->HasSubscribers(channel)) continue;
    const bool same = recorded != nullptr && recording_images_.format == live_images_.format &&
                      (live_images_.format != ImageFormat::kJpeg ||
                       recording_images_.jpeg_quality == live_images_.jpeg_quality);
    const std::string* sent = same ? recorded : EncodeImage(image, f.time, frame, live_images_);
    if (sent == nullptr) continue;
    live_->Publish(channel, f.time, {reinterpret_cast<const uint8_t*>(sent->data()), sent->size()});
    live_published_.fetch_add(1, std::memory_order_relaxed);
  }
}

void TelemetryStage::Loop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { work_.Notify(); });
  constexpr uint64_t kNone = std::numeric_limits<uint64_t>::max();
  while (true) {
    const uint32_t seen = work_.sequence();
    bool worked = false;
    while (true) {
      // Oldest offer first, across all producers.
      const auto* i = imu_.Front();
      const auto* w = wheel_.Front();
      const auto* s = stereo_.Front();
      const auto* p = poses_.Front();
      const auto* m = maps_.Front();
      const uint64_t seq[5] = {i ? i->sequence : kNone, w ? w->sequence : kNone, s ? s->sequence : kNone,
                               p ? p->sequence : kNone, m ? m->sequence : kNone};
      const int k = static_cast<int>(std::min_element(seq, seq + 5) - seq);
      if (seq[k] == kNone) break;
      switch (k) {
        case 0:
          Emit(TelemetryTopic::kImu, i->value.time, encoder_.Imu(i->value));
          imu_.PopFront();
          break;
        case 1:
          Emit(TelemetryTopic::kWheelOdometry, w->value.time, encoder_.WheelOdometry(w->value));
          wheel_.PopFront();
          break;
        case 2:
          HandleStereo(s->value);
          stereo_.PopFront();
          break;
        case 3:
          Emit(TelemetryTopic::kPose, p->value.time, estimates_.Pose(p->value.time, p->value.T_map_body));
          Emit(TelemetryTopic::kTransform, p->value.time, estimates_.Transform(p->value.time, p->value.T_map_body));
          poses_.PopFront();
          break;
        default:
          HandleMap(m->value);
          maps_.PopFront();
          break;
      }
      worked = true;
      space_.Notify();
    }
    if (stop.stop_requested() && imu_.empty() && wheel_.empty() && stereo_.empty() && poses_.empty() &&
        maps_.empty()) {
      return;
    }
    if (!worked) work_.WaitChange(seen);
  }
}

}  // namespace cairn
