#include "daemon/pipeline/pipeline.h"

#include "common/monotonic_clock.h"

#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <optional>
#include <thread>

namespace cairn {
namespace {

int64_t MonotonicNs() { return MonotonicClock().Now().nanoseconds(); }

}  // namespace

Pipeline::Pipeline(const ExecutorsOptions& executors, const QueueOptions& queues, PipelineRates rates,
                   bool deterministic)
    : deterministic_(deterministic),
      imu_queue_(static_cast<size_t>(queues.imu)),
      wheel_queue_(static_cast<size_t>(queues.wheel_odometry)),
      trigger_queue_(static_cast<size_t>(queues.wheel_odometry)),
      stereo_queue_(static_cast<size_t>(queues.stereo)),
      rectified_queue_(static_cast<size_t>(queues.vo)),
      clone_queue_(64),
      vo_result_queue_(32),
      switch_queue_(8),
      estimate_queue_(256),
      estimation_inputs_(imu_queue_, wheel_queue_, trigger_queue_, clone_queue_, vo_result_queue_,
                         switch_queue_),
      dense_queue_(static_cast<size_t>(queues.dense)),
      mapping_estimate_queue_(256),
      switch_event_queue_(16),
      graph_queue_(static_cast<size_t>(queues.graph)),
      submap_queue_(static_cast<size_t>(queues.submaps)),
      detection_queue_(static_cast<size_t>(queues.detection)),
      sighting_queue_(static_cast<size_t>(queues.sightings)),
      gnss_queue_(256),
      imu_deadline_(rates.imu_hz > 0.0 ? Duration::Seconds(1.0 / rates.imu_hz) : Duration::Seconds(0.01)),
      estimation_exec_("estimation", executors.estimation),
      stereo_("stereo", executors.stereo),
      vo_("vo", executors.vo),
      mapping_exec_("mapping", executors.mapping),
      graph_exec_("graph", executors.graph),
      graph_full_solve_exec_("graph_full_solve", executors.graph_full_solve),
      matcher_options_(executors.matcher),
      detection_exec_("detection", executors.detection),
      imu_stats_(rates.imu_hz),
      wheel_stats_(rates.wheel_hz),
      trigger_stats_(rates.camera_hz),
      stereo_stats_(rates.camera_hz) {
  // spdlog creates its default logger on first use, inside its uninstrumented shared library, so
  // ThreadSanitizer cannot see that construction is ordered before the other threads' reads.
  // Creating it here, before any thread logs through the pipeline, makes the order explicit.
  spdlog::default_logger_raw();
}

Pipeline::~Pipeline() { StopAndDrain(); }

Status Pipeline::EnableEstimation(const EstimationSetup& setup) {
  if (started_) return FailedPreconditionError("EnableEstimation() after Start()");
  if (!setup.vo.enabled) return Status::Ok();
  // Buffers for the pairs waiting in the queues, the ones in the odometry and in dense matching,
  // and the one being written.
  auto rectify =
      StereoRectifyStage::Create(setup.stereo, rectified_queue_.capacity() + dense_queue_.capacity() +
                                                   detection_queue_.capacity() + 4);
  if (!rectify.ok()) return rectify.status().WithContext("stereo calibration");
  rectify_ = std::move(*rectify);
  vo_stage_ = std::make_unique<VoStage>(setup.vo, setup.frame_switch, rectify_->camera(), rectify_->T_body_cam());
  estimation_ = std::make_unique<EstimationStage>(setup.filter, setup.imu, setup.wheels, &estimate_queue_);
  return Status::Ok();
}

Status Pipeline::EnableMapping(const MappingSetup& setup) {
  if (started_) return FailedPreconditionError("EnableMapping() after Start()");
  if (!estimation_) return FailedPreconditionError("mapping needs the estimation chain (vo.enabled)");
  MappingSetup with_camera = setup;  // the rectified camera the odometry sees, too
  with_camera.camera = rectify_->camera();
  with_camera.T_body_cam = rectify_->T_body_cam();
  auto stage = MappingStage::Create(with_camera, this);
  if (!stage.ok()) return stage.status();
  mapping_ = std::move(*stage);
  dense_every_ = setup.stereo.every_nth_frame;
  estimation_->AlsoPublishTo(&mapping_estimate_queue_, &switch_event_queue_);
  return Status::Ok();
}

Status Pipeline::EnableGraph(const GraphStageOptions& options) {
  if (started_) return FailedPreconditionError("EnableGraph() after Start()");
  if (!estimation_) return FailedPreconditionError("the graph needs the estimation chain (vo.enabled)");
  graph_ = std::make_unique<GraphStage>(options, deterministic_);
  // Live, full solves after loop closures run on their own executor; replays solve them inline so
  // that the result does not depend on thread timing.
  if (!deterministic_) graph_->SetBackgroundRunner(graph_worker_.Runner());
  gnss_enabled_ = options.gnss.enabled;
  estimation_->PublishToGraph(&graph_queue_);
  return Status::Ok();
}

Status Pipeline::EnableDetection(const RobotDetectionOptions& options, TagCarrierTable table, const std::string& robot,
                                 const std::string& error_table_path, const std::string& region_error_table_path) {
  if (started_) return FailedPreconditionError("EnableDetection() after Start()");
  if (!graph_) return FailedPreconditionError("robot detection needs the graph enabled");
  if (table.empty()) return InvalidArgumentError("robot detection: the tag carrier table lists no tag");
  if (Status s = options.detector.Validate(); !s.ok()) return s.WithContext("detection.detector");
  if (options.every_nth_frame % options.roi_every_nth_frame != 0)
    return InvalidArgumentError("detection.roi_every_nth_frame (" + std::to_string(options.roi_every_nth_frame) +
                                ") must divide detection.every_nth_frame (" + std::to_string(options.every_nth_frame) + ")");
  auto model =
      RobotDetectionStage::MakeErrorModel(options, error_table_path, options.detector.decimate, rectify_->camera());
  if (!model.ok()) return model.status();
  std::optional<TagErrorModel> region_model;
  if (!region_error_table_path.empty()) {
    auto m = RobotDetectionStage::MakeErrorModel(options, region_error_table_path, options.roi_decimate,
                                                 rectify_->camera(), "detection.region_error_table");
    if (!m.ok()) return m.status();
    region_model = std::move(*m);
  }
  graph_->SetLandmarks(table.Landmarks());
  landmark_carriers_ = table.Landmarks();
  for (const auto& [id, mount] : table.tags()) {
    if (mount.landmark || mount.carrier == robot) continue;
    if (std::find(robot_carriers_.begin(), robot_carriers_.end(), mount.carrier) == robot_carriers_.end())
      robot_carriers_.push_back(mount.carrier);
  }
  // A deterministic replay must not depend on how far the graph thread got by each image.
  predict_carriers_ = options.predicted_regions && !deterministic_;
  detection_ = std::make_unique<RobotDetectionStage>(options, std::move(table), std::move(*model), rectify_->camera(),
                                                     rectify_->T_body_cam(), robot, graph_->robot(),
                                                     std::move(region_model));
  // Whole-frame scans on every every_nth_frame-th frame, region scans on every
  // roi_every_nth_frame-th: the stage gets the latter and counts the former among them.
  detection_every_ = options.roi_every_nth_frame;
  return Status::Ok();
}

Status Pipeline::EnableMatching(const SubmapMatchingOptions& options, const std::string& robot) {
  if (started_) return FailedPreconditionError("EnableMatching() after Start()");
  if (!mapping_ || !graph_) return FailedPreconditionError("submap matching needs mapping and the graph enabled");
  if (Status s = options.matcher.Validate(); !s.ok()) return s.WithContext("matching.matcher");
  matching_ = std::make_unique<SubmapMatchingStage>(options, robot, deterministic_, matcher_options_,
                                                    [this] { graph_signal_.Notify(); });
  if (options.plane_landmarks.enabled) {
    planes_ = std::make_unique<PlaneLandmarkStage>(options.plane_landmarks, graph_->robot(), robot);
  }
  if (options.line_landmarks.enabled) {
    lines_ = std::make_unique<LineLandmarkStage>(options.line_landmarks, graph_->robot(), robot);
  }
  mapping_->PublishSubmapsTo(&submap_queue_);
  return Status::Ok();
}

Status Pipeline::SetTeamLink(TeamLink* team, std::map<char, std::string> names) {
  if (started_) return FailedPreconditionError("SetTeamLink() after Start()");
  if (!graph_) return FailedPreconditionError("the team exchange needs the graph enabled");
  team_ = team;
  for (const auto& [letter, name] : names) letters_[name] = letter;
  if (planes_) planes_->SetTeam(names, team);
  if (lines_) lines_->SetTeam(names, team);
  if (matching_) matching_->SetTeam(std::move(names), team);
  team_->SetNotify([this] { graph_signal_.Notify(); });
  // Finished submaps travel to the team even without the matcher.
  if (mapping_) mapping_->PublishSubmapsTo(&submap_queue_);
  return Status::Ok();
}

void Pipeline::SetTelemetry(TelemetryStage* telemetry) {
  telemetry_ = telemetry;
  if (mapping_) mapping_->SetTelemetry(telemetry);
}

MappingStageReport Pipeline::mapping_report() const {
  MappingStageReport r = mapping_ ? mapping_->report() : MappingStageReport{};
  r.switch_requests = mapping_switch_requests_;
  return r;
}

void Pipeline::Start() {
  if (started_) return;
  started_ = true;
  filter_running_.store(true, std::memory_order_release);
  estimation_exec_.Start([this](std::stop_token stop) { EstimationLoop(stop); });
  stereo_.Start([this](std::stop_token stop) { StereoLoop(stop); });
  if (estimation_) vo_.Start([this](std::stop_token stop) { VoLoop(stop); });
  if (mapping_) mapping_exec_.Start([this](std::stop_token stop) { MappingLoop(stop); });
  if (detection_) detection_exec_.Start([this](std::stop_token stop) { DetectionLoop(stop); });
  if (matching_) matching_->Start();
  if (graph_) graph_exec_.Start([this](std::stop_token stop) { GraphLoop(stop); });
  if (graph_ && !deterministic_) {
    graph_full_solve_exec_.Start([this](std::stop_token stop) { graph_worker_.Run(stop); });
  }
}

void Pipeline::StopAndDrain(double max_linger, const std::function<bool()>& cut_linger) {
  if (!started_) return;
  // Upstream first, so that every stage drains into a consumer that still runs (in deterministic
  // mode a producer waits for its consumer).
  stereo_.RequestStop();
  stereo_signal_.Notify();
  stereo_.Join();
  if (estimation_) {
    vo_.RequestStop();
    vo_signal_.Notify();
    vo_.Join();
  }
  if (detection_) {
    detection_exec_.RequestStop();
    detection_signal_.Notify();
    detection_exec_.Join();
  }
  // Mapping after the odometry (its pairs are all in) but before the filter: in deterministic
  // mode its frame-switch requests wait for the estimation thread.
  if (mapping_) {
    mapping_exec_.RequestStop();
    mapping_signal_.Notify();
    mapping_exec_.Join();
  }
  filter_running_.store(false, std::memory_order_release);
  estimation_exec_.RequestStop();
  estimation_signal_.Notify();
  estimation_exec_.Join();
  // The last submaps are finished before the graph stops, so that they are matched too.
  if (mapping_ && matching_) {
    TakeMappingInputs();
    mapping_->FinishSubmaps();
  }
  // The graph takes everything the filter made, then solves to convergence.
  if (graph_) {
    graph_exec_.RequestStop();
    graph_signal_.Notify();
    graph_exec_.Join();
    if (detection_) TakeSightings(Timestamp::FromNanoseconds(INT64_MAX));
    if (gnss_enabled_) TakeGnssFixes(Timestamp::Max());
    if (team_) {
      // The last own items go out; teammates' keep coming until the team holds the same logs
      // (or the linger time is over). This thread owns the graph now.
      TakeSubmaps(UINT64_MAX);
      team_->FinishOwnLog();
      const auto start = std::chrono::steady_clock::now();
      const double limit = std::min(team_->linger_seconds(), max_linger);
      const auto deadline = start + std::chrono::duration<double>(limit);
      spdlog::info("team: exchanging until every teammate holds the same items, at most {:.0f} s", limit);
      bool cut = false;
      while (!team_->Settled() && std::chrono::steady_clock::now() < deadline) {
        cut = cut_linger && cut_linger();
        if (cut) break;
        const bool took = TakeTeamInputs();
        StepSubmapWork();
        team_->SetIdle(!took && (matching_ == nullptr || matching_->Idle()));
        if (!took) std::this_thread::sleep_for(std::chrono::milliseconds(20));
      }
      linger_.ended = team_->Settled() ? "settled" : cut ? "cut" : "time";
      linger_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      TakeTeamInputs();
    }
    if (matching_) {
      TakeSubmaps(UINT64_MAX);
      matching_->Drain(*graph_);
      if (planes_) planes_->Step(*graph_);
      if (lines_) lines_->Step(*graph_);
    }
    graph_->Finish();  // waits for a running full solve, so its worker stops after it
    graph_full_solve_exec_.RequestStop();
    graph_full_solve_exec_.Join();
  }
  // What the filter emitted last is mapped too; the open submap is finished and the map written.
  if (mapping_) {
    TakeMappingInputs();
    if (graph_) {
      const auto origins = graph_->FrameOrigins();
      // Teammates' submaps (and this robot's of earlier runs) whose runs the graph has tied to
      // this one's frame.
      std::vector<PlacedSubmap> team;
      for (const auto& [letter, submaps] : team_submaps_) {
        const auto team_origins = graph_->FrameOrigins(letter);
        for (const auto& [frame, submap] : submaps) {
          if (!graph_->Connected(letter, RunOfIndex(frame))) continue;
          const auto o = team_origins.find(frame);
          if (o != team_origins.end()) team.push_back(PlacedSubmap{submap, o->second});
        }
      }
      mapping_->Finish(&origins, &team);
    } else {
      mapping_->Finish();
    }
  }
  // Estimates emitted after the odometry stopped.
  if (vo_stage_) {
    while (const FrameEstimate* e = estimate_queue_.Front()) {
      vo_stage_->OnEstimate(*e);
      if (e->valid && telemetry_ != nullptr) telemetry_->OfferPose(e->time, e->T_first_body);
      estimate_queue_.PopFront();
    }
  }
  started_ = false;
}

template <class T>
void Pipeline::Publish(SpscQueue<Queued<T>>& queue, const T& value, WorkSignal& signal) {
  const Queued<T> item{MonotonicNs(), value};
  if (!deterministic_) {
    if (queue.TryPush(item)) signal.Notify();
    return;
  }
  // Deterministic: enqueue, then wait until the stage has consumed this very item.
  const uint64_t target = queue.pushed() + 1;
  while (!queue.TryPush(item)) std::this_thread::yield();
  signal.Notify();
  while (true) {
    const uint32_t seen = consumed_signal_.sequence();
    if (queue.popped() >= target) break;
    consumed_signal_.WaitChange(seen);
  }
}

void Pipeline::OnImu(const ImuSample& s) {
  if (gnss_enabled_) last_imu_ns_.store(s.time.nanoseconds(), std::memory_order_relaxed);
  Publish(imu_queue_, s, estimation_signal_);
}
void Pipeline::OnWheelOdometry(const WheelOdometrySample& s) { Publish(wheel_queue_, s, estimation_signal_); }
void Pipeline::OnTrigger(const TriggerEvent& e) { Publish(trigger_queue_, e, estimation_signal_); }
void Pipeline::OnStereo(const StereoFrame& f) { Publish(stereo_queue_, f, stereo_signal_); }
void Pipeline::OnGnss(const GnssFix& fix) {
  if (!gnss_enabled_) return;
  const QueuedFix item{
      fix, std::max(fix.time, Timestamp::FromNanoseconds(last_imu_ns_.load(std::memory_order_relaxed)))};
  // Never held until consumed, even in deterministic runs: the graph takes a fix at the first
  // estimate after `after`, and that estimate needs the samples this publisher sends next.
  if (deterministic_) {
    while (!gnss_queue_.TryPush(item)) std::this_thread::yield();
  } else if (!gnss_queue_.TryPush(item)) {
    return;  // a full queue counts the drop
  }
  graph_signal_.Notify();
}

void Pipeline::OnDeviceFault(const DeviceFault& fault) {
  // Faults are rare and come from driver threads: a lock here never touches a real-time path.
  {
    std::lock_guard lock(fault_mutex_);
    ++faults_.counts[fault.device][DeviceFaultKindName(fault.kind)];
    ++faults_.total;
    if (faults_.first_messages.size() < 20) {
      faults_.first_messages.push_back(fault.device + ": " + DeviceFaultKindName(fault.kind) +
                                       ": " + fault.detail);
    }
  }
  spdlog::warn("device fault: {}: {}: {}", fault.device, DeviceFaultKindName(fault.kind), fault.detail);
}

void Pipeline::RequestFilterSwitch(const FilterSwitchRequest& request) {
  Publish(switch_queue_, request, estimation_signal_);
}

void Pipeline::RequestFrameSwitch(const FrameSwitchRequest& request) {
  // At the end of a run the filter has stopped: the last submap is finished without a switch.
  if (!filter_running_.load(std::memory_order_acquire)) return;
  ++mapping_switch_requests_;
  RequestFilterSwitch(FilterSwitchRequest{request.time, request.reason == PartitionReason::kDistance
                                                            ? FrameSwitchReason::kDistance
                                                            : FrameSwitchReason::kPositionSigma});
}

void Pipeline::EstimationLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { estimation_signal_.Notify(); });
  while (true) {
    const uint32_t seen = estimation_signal_.sequence();
    bool worked = false;
    while (const std::optional<EstimationInput> next = estimation_inputs_.Next()) {
      const int64_t now = MonotonicNs();
      switch (*next) {
        case EstimationInput::kImu: {
          const Queued<ImuSample>& imu = *imu_queue_.Front();
          const Duration latency = Duration::Nanoseconds(now - imu.enqueued_ns);
          imu_latency_.Record(latency);
          if (latency > imu_deadline_) deadline_misses_.fetch_add(1, std::memory_order_relaxed);
          imu_stats_.Add(imu.value.time);
          if (estimation_) {
            estimation_->OnImu(imu.value);
            imu_to_estimate_.Record(Duration::Nanoseconds(MonotonicNs() - imu.enqueued_ns));
          }
          if (telemetry_ != nullptr) telemetry_->OfferImu(imu.value);
          // Live mode: wake mapping when an estimate it waits for came out (deterministic replays
          // map at fixed points of the data flow instead, see MappingLoop).
          if (mapping_ && !deterministic_ && mapping_estimate_queue_.pushed() != mapping_estimates_seen_) {
            mapping_estimates_seen_ = mapping_estimate_queue_.pushed();
            mapping_signal_.Notify();
          }
          imu_queue_.PopFront();
          break;
        }
        case EstimationInput::kWheel: {
          const Queued<WheelOdometrySample>& wheel = *wheel_queue_.Front();
          wheel_latency_.Record(Duration::Nanoseconds(now - wheel.enqueued_ns));
          wheel_stats_.Add(wheel.value.time);
          if (estimation_) estimation_->OnWheel(wheel.value);
          if (telemetry_ != nullptr) telemetry_->OfferWheelOdometry(wheel.value);
          wheel_queue_.PopFront();
          break;
        }
        case EstimationInput::kTrigger:
          trigger_stats_.Add(trigger_queue_.Front()->value.time);
          trigger_queue_.PopFront();
          break;
        case EstimationInput::kClone:
          estimation_->OnFrame(clone_queue_.Front()->value);
          clone_queue_.PopFront();
          break;
        case EstimationInput::kVoResult:
          estimation_->OnVoResult(vo_result_queue_.Front()->value);
          vo_result_queue_.PopFront();
          break;
        case EstimationInput::kFrameSwitch:
          estimation_->OnFrameSwitch(switch_queue_.Front()->value);
          switch_queue_.PopFront();
          break;
      }
      worked = true;
      if (deterministic_) consumed_signal_.Notify();
      if (graph_ && graph_queue_.pushed() != graph_inputs_seen_) {
        graph_inputs_seen_ = graph_queue_.pushed();
        graph_signal_.Notify();
      }
    }
    if (stop.stop_requested() && estimation_inputs_.empty()) return;
    if (!worked) estimation_signal_.WaitChange(seen);
  }
}

void Pipeline::StereoLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { stereo_signal_.Notify(); });
  const MonotonicClock clock;
  while (true) {
    const uint32_t seen = stereo_signal_.sequence();
    bool worked = false;
    while (const auto* queued = stereo_queue_.Front()) {
      stereo_latency_.Record(Duration::Nanoseconds(MonotonicNs() - queued->enqueued_ns));
      const StereoFrame* f = &queued->value;
      stereo_stats_.Add(f->time);
      int gap = 0;
      if (stereo_stats_.count() > 1 && f->frame_counter > last_frame_counter_ + 1) {
        gap = static_cast<int>(std::min<uint64_t>(f->frame_counter - last_frame_counter_ - 1, 1 << 20));
        stereo_report_.frame_counter_gaps += f->frame_counter - last_frame_counter_ - 1;
      }
      last_frame_counter_ = f->frame_counter;
      if (f->left.width != stereo_report_.width || f->left.height != stereo_report_.height) {
        if (stereo_stats_.count() > 1) ++stereo_report_.size_changes;
        stereo_report_.width = f->left.width;
        stereo_report_.height = f->left.height;
      }
      if (telemetry_ != nullptr) telemetry_->OfferStereo(*f);
      if (estimation_) {
        // The filter clones its state at the exposure time now; the odometry's delta pose
        // references that clone when it arrives.
        Publish(clone_queue_, f->time, estimation_signal_);
        const Timestamp start = clock.Now();
        RectifiedPair pair;
        pending_dropped_ += gap;
        if (rectify_->Rectify(*f, &pair)) {
          rectify_time_.Record(clock.Now() - start);
          pair.dropped_before = pending_dropped_;
          pending_dropped_ = 0;
          Publish(rectified_queue_, pair, vo_signal_);
          if (mapping_ && dense_counter_++ % static_cast<uint64_t>(dense_every_) == 0) {
            Publish(dense_queue_, pair, mapping_signal_);
          }
          if (detection_ && detection_counter_++ % static_cast<uint64_t>(detection_every_) == 0) {
            Publish(detection_queue_, pair, detection_signal_);
          }
        } else {
          ++rectify_failures_;
        }
      }
      stereo_queue_.PopFront();
      worked = true;
      if (deterministic_) consumed_signal_.Notify();
    }
    if (stop.stop_requested() && stereo_queue_.empty()) return;
    if (!worked) stereo_signal_.WaitChange(seen);
  }
}

void Pipeline::DrainEstimates() {
  while (const FrameEstimate* e = estimate_queue_.Front()) {
    const std::optional<FilterSwitchRequest> request = vo_stage_->OnEstimate(*e);
    if (e->valid && telemetry_ != nullptr) telemetry_->OfferPose(e->time, e->T_first_body);
    estimate_queue_.PopFront();
    if (request) RequestFilterSwitch(*request);
  }
}

void Pipeline::VoLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { vo_signal_.Notify(); });
  while (true) {
    const uint32_t seen = vo_signal_.sequence();
    bool worked = false;
    while (const auto* queued = rectified_queue_.Front()) {
      // The filter's estimates are taken in right before each frame (a fixed point in the data
      // flow, so deterministic replays switch frames at the same instants).
      DrainEstimates();
      const VoResult r = vo_stage_->Process(queued->value);
      Publish(vo_result_queue_, r, estimation_signal_);
      rectified_queue_.PopFront();
      worked = true;
      if (deterministic_) consumed_signal_.Notify();
    }
    if (stop.stop_requested() && rectified_queue_.empty()) return;
    if (!worked) vo_signal_.WaitChange(seen);
  }
}

void Pipeline::TakeMappingInputs() {
  while (const FrameEstimate* e = mapping_estimate_queue_.Front()) {
    mapping_->OnEstimate(*e);
    mapping_estimate_queue_.PopFront();
  }
  while (const FrameSwitchEvent* e = switch_event_queue_.Front()) {
    mapping_->OnFrameSwitch(*e);
    switch_event_queue_.PopFront();
  }
}

void Pipeline::StepSubmapWork() {
  if (matching_) matching_->Step(*graph_);
  // After the matcher: its matches tie teammates' origins, which places their faces and edges.
  if (planes_) planes_->Step(*graph_);
  if (lines_) lines_->Step(*graph_);
}

void Pipeline::TakeSubmaps(uint64_t max_id) {
  while (const std::shared_ptr<const Submap>* s = submap_queue_.Front()) {
    if ((*s)->metadata().id > max_id) return;
    if (planes_) planes_->OnSubmap(graph_->robot(), (*s)->metadata().id, **s);
    if (lines_) lines_->OnSubmap(graph_->robot(), (*s)->metadata().id, **s);
    if (matching_) matching_->OnSubmap(*s);
    if (team_) team_->PublishSubmap(*s);
    submap_queue_.PopFront();
  }
}

void Pipeline::PublishToTeam(const GraphInput& input) {
  if (input.kind == GraphInput::Kind::kFrameSwitch) {
    team_->PublishFrameSwitch(input.frame_switch);
    return;
  }
  if (!input.estimate.valid) return;
  uint64_t index = 0;
  const bool pose = graph_->last_estimate_is_pose(&index);
  team_->PublishEstimate(input.estimate, pose, index);
}

bool Pipeline::TakeTeamInputs() {
  bool any = false;
  TeamInput in;
  while (team_->NextInput(&in)) {
    any = true;
    if (in.kind == TeamInput::Kind::kSubmap && in.submap) {
      team_submaps_[in.letter][in.new_frame] = in.submap;
      if (matching_) matching_->OnTeamSubmap(in.robot, in.new_frame, in.submap);
      if (planes_) planes_->OnSubmap(in.letter, in.new_frame, *in.submap);
      if (lines_) lines_->OnSubmap(in.letter, in.new_frame, *in.submap);
    }
    if (planes_ && in.kind == TeamInput::Kind::kPlaneObservations) planes_->OnTeamObservations(in.planes);
    if (lines_ && in.kind == TeamInput::Kind::kLineObservations) lines_->OnTeamObservations(in.lines);
    if (matching_ && (in.kind == TeamInput::Kind::kAttempt || in.kind == TeamInput::Kind::kMatch)) {
      matching_->OnTeamAttempt(in.match, in.kind == TeamInput::Kind::kMatch || in.matched);
    }
    graph_->OnTeamInput(in);
  }
  return any;
}

void Pipeline::ShowTeamSubmaps() {
  // The joint map live: each teammate's submap once its run is tied to this robot's frame, where
  // the graph puts its origin then.
  for (const auto& [letter, submaps] : team_submaps_) {
    std::map<uint64_t, Eigen::Isometry3d> origins;
    for (const auto& [frame, submap] : submaps) {
      if (team_submaps_shown_.count({letter, frame}) != 0 || !graph_->Connected(letter, RunOfIndex(frame))) continue;
      if (origins.empty()) origins = graph_->FrameOrigins(letter);
      const auto o = origins.find(frame);
      if (o == origins.end()) continue;
      telemetry_->OfferSubmap(submap->metadata().end, submap, o->second);
      team_submaps_shown_.insert({letter, frame});
    }
  }
}

void Pipeline::DetectionLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { detection_signal_.Notify(); });
  std::vector<TagSighting> found;
  CarrierPredictions predictions;
  while (true) {
    const uint32_t seen = detection_signal_.sequence();
    bool worked = false;
    while (const auto* queued = detection_queue_.Front()) {
      found.clear();
      if (predict_carriers_) {
        const std::lock_guard lock(predictions_mutex_);
        predictions = predictions_;
      }
      detection_->Process(queued->value, predict_carriers_ ? &predictions : nullptr, &found);
      for (TagSighting& s : found) {
        if (deterministic_) {
          while (!sighting_queue_.TryPush(s)) std::this_thread::yield();
        } else {
          sighting_queue_.TryPush(s);  // a full queue counts the drop
        }
      }
      if (!found.empty()) graph_signal_.Notify();
      // Popped only now: in deterministic mode the publisher waits until the sightings are queued.
      detection_queue_.PopFront();
      worked = true;
      if (deterministic_) consumed_signal_.Notify();
    }
    if (stop.stop_requested() && detection_queue_.empty()) return;
    if (!worked) detection_signal_.WaitChange(seen);
  }
}

void Pipeline::PublishPredictions() {
  CarrierPredictions& p = predictions_scratch_;
  StampedPose own;
  if (!graph_->LatestGlobalPose(graph_->robot(), &own)) return;
  p.valid = true;
  p.time = own.time;
  p.T_global_body = own.T_frame_body;
  // The others move slowly or not at all; placing them costs a pass over the graph's variables.
  if (own.time - carriers_placed_time_ >= Duration::Seconds(1.0)) {
    carriers_placed_time_ = own.time;
    p.carriers.clear();
    for (const std::string& name : robot_carriers_) {
      const auto letter = letters_.find(name);
      StampedPose pose;
      if (letter == letters_.end() || !graph_->LatestGlobalPose(letter->second, &pose)) continue;
      p.carriers.push_back({name, false, pose.time, pose.T_frame_body});
    }
    for (size_t i = 0; i < landmark_carriers_.size(); ++i) {
      Eigen::Isometry3d T_global_landmark;
      if (graph_->LandmarkGlobalPose(i, &T_global_landmark))
        p.carriers.push_back({landmark_carriers_[i], true, own.time, T_global_landmark});
    }
  }
  const std::lock_guard lock(predictions_mutex_);
  predictions_ = p;
}

void Pipeline::TakeSightings(Timestamp before) {
  while (const TagSighting* s = sighting_queue_.Front()) {
    if (!(s->detection.time < before)) return;
    TeamDetection d = s->detection;
    if (!d.landmark) {
      const auto it = letters_.find(d.observed);
      if (it != letters_.end()) d.observed_letter = it->second;
    }
    graph_->AddDetection(d, s->usable, s->refused);
    if (team_ && s->usable) team_->PublishDetection(d);
    sighting_queue_.PopFront();
  }
}

void Pipeline::TakeGnssFixes(Timestamp before) {
  while (const QueuedFix* queued = gnss_queue_.Front()) {
    if (!(queued->after < before)) return;
    if (graph_->AddGnssFix(queued->fix) && team_) {
      team_->PublishGnssFix(TeamGnssFix{graph_->robot(), kCurrentRun, queued->fix, graph_->gnss_antenna()});
    }
    gnss_queue_.PopFront();
  }
}

void Pipeline::MappingLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { mapping_signal_.Notify(); });
  while (true) {
    const uint32_t seen = mapping_signal_.sequence();
    bool worked = false;
    if (!deterministic_) {
      TakeMappingInputs();
      mapping_->ProcessReady(/*final=*/false);
    }
    while (const auto* queued = dense_queue_.Front()) {
      if (deterministic_) {
        // A fixed point of the data flow: everything the filter says about the earlier pairs is
        // in (the publisher is held until this pair is taken), so the images waiting for those
        // estimates are mapped, and any frame switch requested, at the same instant every run.
        TakeMappingInputs();
        mapping_->ProcessReady(/*final=*/false);
      }
      const RectifiedPair pair = queued->value;  // holds the image buffers
      dense_queue_.PopFront();
      if (deterministic_) consumed_signal_.Notify();
      mapping_->OnPair(pair);
      if (!deterministic_) {
        TakeMappingInputs();
        mapping_->ProcessReady(/*final=*/false);
      }
      worked = true;
    }
    if (stop.stop_requested() && dense_queue_.empty()) return;
    if (!worked) mapping_signal_.WaitChange(seen);
  }
}

void Pipeline::GraphLoop(std::stop_token stop) {
  std::stop_callback wake(stop, [this] { graph_signal_.Notify(); });
  while (true) {
    const uint32_t seen = graph_signal_.sequence();
    bool worked = false;
    while (const GraphInput* in = graph_queue_.Front()) {
      // Deterministic: the sightings of the images before this estimate are in (the publisher is
      // held until each image's detection is done), a fixed point of the data flow.
      if (detection_ && in->kind == GraphInput::Kind::kEstimate) TakeSightings(in->estimate.time);
      // Likewise the fixes: each was published before the IMU samples of any estimate after its `after`.
      if (gnss_enabled_ && in->kind == GraphInput::Kind::kEstimate) TakeGnssFixes(in->estimate.time);
      graph_->OnInput(*in);
      if (team_) PublishToTeam(*in);
      // Submap k is finished before mapping asks to leave frame k + 1, so once the switch into
      // frame n is in, every submap up to n - 2 is in the queue: a fixed point of the data flow.
      const bool into_frame = in->kind == GraphInput::Kind::kFrameSwitch;
      const uint64_t frame = in->frame_switch.new_frame_id;
      graph_queue_.PopFront();
      worked = true;
      if (matching_ && into_frame && frame >= 2) {
        TakeSubmaps(deterministic_ ? frame - 2 : UINT64_MAX);
        StepSubmapWork();
      }
    }
    if (detection_ && !deterministic_) TakeSightings(Timestamp::FromNanoseconds(INT64_MAX));
    if (gnss_enabled_ && (!deterministic_ || stop.stop_requested())) TakeGnssFixes(Timestamp::Max());
    if (worked && predict_carriers_) PublishPredictions();
    if (matching_ && !deterministic_) {
      TakeSubmaps(UINT64_MAX);
      StepSubmapWork();
    }
    if (team_) {
      if (!matching_) TakeSubmaps(UINT64_MAX);
      worked |= TakeTeamInputs();
    }
    // The live view: at each new origin, else about once a second of data.
    const bool new_origin = graph_->submap_origins() != graph_shown_origins_;
    if (worked && telemetry_ != nullptr && telemetry_->live() &&
        (new_origin || graph_->last_time() - graph_shown_time_ >= Duration::Seconds(1.0))) {
      graph_shown_origins_ = graph_->submap_origins();
      graph_shown_time_ = graph_->last_time();
      telemetry_->PublishGraph(graph_shown_time_,
                               graph_scene_.Encode(graph_shown_time_, graph_->robot(), graph_->Scene(new_origin)));
      ShowTeamSubmaps();
    }
    // The estimation thread has stopped before this is asked: its last inputs are in the queue.
    if (stop.stop_requested() && graph_queue_.empty()) return;
    if (!worked) graph_signal_.WaitChange(seen);
  }
}

std::vector<QueueReport> Pipeline::queue_reports() const {
  const auto r = [](const char* name, const auto& q) {
    return QueueReport{name, q.capacity(), q.pushed(), q.dropped(), q.high_water()};
  };
  std::vector<QueueReport> out = {r("imu", imu_queue_), r("wheel_odometry", wheel_queue_),
                                  r("trigger", trigger_queue_), r("stereo", stereo_queue_)};
  if (estimation_) {
    for (QueueReport q : {r("vo", rectified_queue_), r("clone", clone_queue_), r("vo_result", vo_result_queue_),
                          r("frame_switch", switch_queue_), r("estimate", estimate_queue_)}) {
      out.push_back(q);
    }
  }
  if (mapping_) {
    for (QueueReport q : {r("dense", dense_queue_), r("mapping_estimate", mapping_estimate_queue_),
                          r("frame_switch_event", switch_event_queue_)}) {
      out.push_back(q);
    }
  }
  if (graph_) out.push_back(r("graph", graph_queue_));
  if (gnss_enabled_) out.push_back(r("gnss", gnss_queue_));
  if (matching_) out.push_back(r("submaps", submap_queue_));
  if (detection_) {
    out.push_back(r("detection", detection_queue_));
    out.push_back(r("sightings", sighting_queue_));
  }
  return out;
}

uint64_t Pipeline::total_dropped() const {
  return imu_queue_.dropped() + wheel_queue_.dropped() + trigger_queue_.dropped() + stereo_queue_.dropped() +
         rectified_queue_.dropped() + clone_queue_.dropped() + vo_result_queue_.dropped() +
         switch_queue_.dropped() + estimate_queue_.dropped() + dense_queue_.dropped() +
         mapping_estimate_queue_.dropped() + switch_event_queue_.dropped() + graph_queue_.dropped() +
         submap_queue_.dropped() + detection_queue_.dropped() + sighting_queue_.dropped() +
         gnss_queue_.dropped();
}

std::vector<LatencyReport> Pipeline::latency_reports() const {
  const auto r = [](const char* name, const LatencyHistogram& h) {
    return LatencyReport{name,
                         h.count(),
                         h.Quantile(0.5).seconds(),
                         h.Quantile(0.99).seconds(),
                         h.Quantile(0.999).seconds(),
                         h.max().seconds(),
                         h.over_1ms()};
  };
  return {r("imu", imu_latency_), r("imu_to_estimate", imu_to_estimate_), r("wheel_odometry", wheel_latency_),
          r("stereo", stereo_latency_)};
}

std::vector<ExecutorReport> Pipeline::executor_reports() const {
  std::vector<ExecutorReport> out = {estimation_exec_.report(), stereo_.report()};
  if (estimation_) out.push_back(vo_.report());
  if (mapping_) out.push_back(mapping_exec_.report());
  if (graph_) out.push_back(graph_exec_.report());
  if (detection_) out.push_back(detection_exec_.report());
  if (graph_ && !deterministic_) out.push_back(graph_full_solve_exec_.report());
  if (matching_) {
    for (const ExecutorReport& w : matching_->executor_reports()) out.push_back(w);
  }
  return out;
}

std::vector<StageTimingReport> Pipeline::stage_timing_reports() const {
  if (!vo_stage_) return {};
  const auto r = [](const char* name, const LatencyHistogram& h) {
    return StageTimingReport{name, h.count(), h.Quantile(0.5).seconds(), h.Quantile(0.99).seconds(), h.max().seconds()};
  };
  std::vector<StageTimingReport> out = {r("rectify", rectify_time_), r("vo", vo_stage_->vo_time())};
  if (mapping_) {
    out.push_back(r("dense_stereo", mapping_->match_time()));
    out.push_back(r("mapping", mapping_->map_time()));
    out.push_back(r("lines", mapping_->line_time()));
  }
  if (graph_) out.push_back(r("graph_update", graph_->update_time()));
  if (detection_) {
    out.push_back(r("tag_detection", detection_->time()));
    out.push_back(r("tag_detection_regions", detection_->region_time()));
  }
  return out;
}

EstimationReport Pipeline::estimation_report() const {
  return estimation_ ? estimation_->report() : EstimationReport{};
}

FaultReport Pipeline::fault_report() const {
  std::lock_guard lock(fault_mutex_);
  return faults_;
}

}  // namespace cairn
