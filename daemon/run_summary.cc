#include "daemon/run_summary.h"

#include "common/heap_bytes.h"
#include "common/json_writer.h"

#include <cmath>
#include <filesystem>
#include <numbers>
#include <optional>

namespace cairn {
namespace {

void WriteStream(JsonWriter& j, std::string_view name, const SensorStreamStats& s) {
  j.Key(name).BeginObject();
  j.Field("count", s.count());
  if (s.count() > 0) {
    j.Field("first_time_ns", s.first().nanoseconds());
    j.Field("last_time_ns", s.last().nanoseconds());
  }
  j.Field("duration_s", s.duration());
  j.Field("mean_rate_hz", s.mean_rate_hz());
  if (s.nominal_rate_hz() > 0.0) j.Field("nominal_rate_hz", s.nominal_rate_hz());
  j.Field("max_gap_s", s.max_gap());
  j.Field("gaps", s.gaps());
  j.Field("out_of_order", s.out_of_order());
  j.Field("duplicates", s.duplicates());
  j.EndObject();
}

// What the graph holds of one landmark kind: landmarks, observations, observations waiting.
struct GraphCounts {
  uint64_t landmarks = 0, observations = 0, pending = 0;
};

void WriteStructureLandmarks(JsonWriter& j, const char* name, const char* features,
                             const StructureLandmarkReport& r, const std::optional<GraphCounts>& g) {
  j.Key(name).BeginObject();
  j.Field("submaps", r.submaps).Field(features, r.features).Field("pairs", r.pairs);
  j.Field("associations", r.associations).Field("observations", r.observations);
  j.Field("team_observations", r.team_observations).Field("refused", r.refused).Field("waiting", r.waiting);
  if (g) {
    j.Field("graph_landmarks", g->landmarks).Field("graph_observations", g->observations);
    j.Field("graph_pending", g->pending);
  }
  j.Key("first_errors").BeginArray();
  for (const auto& e : r.errors) j.String(e);
  j.EndArray();
  j.EndObject();
}

}  // namespace

std::string BuildSummaryJson(const RunInfo& run, const Pipeline& p) {
  JsonWriter j;
  j.BeginObject();
  j.Field("robot", run.robot);
  j.Field("mode", run.mode);
  j.Field("stop_reason", run.stop_reason);
  j.Field("complete", run.complete);
  if (run.replay) {
    const ReplayInfo& r = *run.replay;
    j.Key("replay").BeginObject();
    j.Field("dataset", r.dataset);
    j.Field("pacing", r.pacing);
    j.Field("deterministic", r.deterministic);
    j.Field("imu_samples", r.imu_samples);
    j.Field("stereo_pairs", r.stereo_pairs);
    j.Field("unpaired_left", r.unpaired_left);
    j.Field("unpaired_right", r.unpaired_right);
    j.EndObject();
  }
  j.Key("streams").BeginObject();
  WriteStream(j, "imu", p.imu_stats());
  WriteStream(j, "stereo", p.stereo_stats());
  WriteStream(j, "wheel_odometry", p.wheel_stats());
  WriteStream(j, "trigger", p.trigger_stats());
  j.EndObject();
  const StereoStageReport& sr = p.stereo_report();
  j.Key("stereo").BeginObject();
  j.Field("width", sr.width).Field("height", sr.height);
  j.Field("frame_counter_gaps", sr.frame_counter_gaps);
  j.Field("size_changes", sr.size_changes);
  j.EndObject();
  j.Key("dropped").BeginObject();
  for (const QueueReport& q : p.queue_reports()) j.Field(q.name, q.dropped);
  j.EndObject();
  if (run.trigger_stamping) {
    const TriggerFrameStamperCounts& t = *run.trigger_stamping;
    j.Key("trigger_stamping").BeginObject();
    j.Field("edges", t.edges).Field("stamped_frames", t.stamped).Field("unmatched_frames", t.unmatched);
    j.Field("edges_without_frame", t.lonely_edges).Field("delay_relearned", t.relearns);
    j.Field("delay_learned", t.delay_learned);
    if (t.delay_learned) j.Field("delay_s", t.delay);
    j.EndObject();
  }
  if (run.recording) {
    j.Key("recording").BeginObject();
    j.Key("files").BeginArray();
    for (const auto& f : run.recording->files) j.String(std::filesystem::path(f).filename().string());
    j.EndArray();
    j.Key("messages").BeginObject();
    for (const auto& [topic, n] : run.recording->messages) j.Field(topic, n);
    j.EndObject();
    j.Field("bytes", run.recording->bytes);
    j.Field("dropped", run.telemetry_dropped);
    j.Field("write_errors", run.recording->write_errors);
    j.Field("image_codec_failures", run.image_codec_failures);
    j.EndObject();
  }
  if (p.estimation_enabled()) {
    const EstimationReport e = p.estimation_report();
    const VoStageReport& v = *p.vo_report();
    j.Key("estimation").BeginObject();
    j.Field("filter_initialized", e.initialized);
    j.Field("camera_frames", v.frames);
    j.Field("rectify_failures", p.rectify_failures());
    j.Field("trajectory_poses", p.trajectory()->poses.size());
    j.Field("vo_poses", p.odometry()->poses.size());
    j.Key("vo").BeginObject();
    j.Field("keyframes", v.keyframes);
    uint64_t failures = 0;
    j.Key("status").BeginObject();
    for (int i = 0; i < kVoStatusCount; ++i) {
      const VoStatus st = static_cast<VoStatus>(i);
      j.Field(VoStatusName(st), v.by_status[static_cast<size_t>(i)]);
      if (st != VoStatus::kOk && st != VoStatus::kNoKeyframe) failures += v.by_status[static_cast<size_t>(i)];
    }
    j.EndObject();
    j.Field("failures", failures);
    j.Field("keyframes_dropped_for_missing_clone", v.keyframes_dropped_for_missing_clone);
    j.EndObject();
    j.Key("filter").BeginObject();
    j.Field("imu_accepted", e.filter.imu_accepted);
    j.Field("clones_requested", e.filter.clones_requested);
    j.Field("clones_refused", e.clones_failed);
    j.Field("clones_marginalized", e.filter.clones_marginalized);
    j.Field("vo_results", e.vo_results);
    j.Field("vo_updates_applied", e.vo_updates_applied);
    j.Field("vo_updates_rejected", e.vo_updates_rejected);
    j.Field("vo_results_without_clone", e.vo_missing_clone);
    j.Field("updates_applied", e.filter.updates_applied);
    j.Field("updates_rejected", e.filter.updates_rejected);
    j.Field("replays", e.filter.replays);
    j.EndObject();
    j.Key("frame_switches").BeginObject();
    j.Field("count", e.frame_switches);
    j.Field("distance", e.switch_reasons[static_cast<size_t>(FrameSwitchReason::kDistance)]);
    j.Field("position_sigma", e.switch_reasons[static_cast<size_t>(FrameSwitchReason::kPositionSigma)]);
    j.EndObject();
    j.Field("estimates_dropped", e.estimates_dropped);
    j.EndObject();
  }
  if (p.mapping_enabled()) {
    const MappingStageReport m = p.mapping_report();
    j.Key("mapping").BeginObject();
    j.Key("dense_stereo").BeginObject();
    j.Field("backend", m.backend);
    if (!m.device.empty()) j.Field("device", m.device);
    j.Field("pairs", m.pairs);
    j.Field("failures", m.match_failures);
    j.Field("bidirectional", m.bidirectional);
    // Matcher passes: two per pair when bidirectional.
    j.Field("fpga_frames", m.fpga_frames).Field("cpu_frames", m.cpu_frames);
    j.Field("fpga_failures", m.fpga_failures);
    if (!m.fpga_status.empty()) j.Field("fpga_unused_because", m.fpga_status);
    j.EndObject();
    j.Field("images_mapped", m.images_mapped);
    j.Field("images_without_pose", m.images_without_pose);
    j.Field("images_dropped", m.images_dropped);
    j.Field("estimates_dropped", m.estimates_dropped);
    j.Field("errors", m.mapping_errors);
    j.Field("points", m.mapper.points).Field("obstacle_points", m.mapper.obstacle_points);
    j.Field("fused_pixels", m.mapper.fused_pixels).Field("unmapped_points", m.mapper.unmapped_points);
    j.Field("switch_requests", m.switch_requests);
    j.Field("frame_switches", m.frame_switches);
    j.Field("unannounced_frame_changes", m.mapper.unannounced_frame_changes);
    j.Key("submaps").BeginObject();
    j.Field("finished", m.submaps_finished).Field("written", m.submaps_written);
    j.Field("write_failures", m.submap_write_failures).Field("bytes", m.submap_bytes);
    j.EndObject();
    j.Field("map_points", m.map_points).Field("map_voxels", m.map_voxels);
    j.Field("submaps_placed_by_graph", m.submaps_placed_by_graph);
    j.Key("lines").BeginObject();
    j.Field("segments", m.line_segments).Field("triangulated", m.line_sightings);
    j.Field("joined", m.mapper.line_sightings).Field("in_submaps", m.submap_lines);
    j.EndObject();
    j.Key("first_errors").BeginArray();
    for (const auto& e : m.errors) j.String(e);
    j.EndArray();
    j.EndObject();
  }
  if (const GraphStage* graph = p.graph()) {
    const GraphStageReport g = graph->report();
    j.Key("graph").BeginObject();
    j.Field("estimates", g.estimates);
    j.Field("inputs_dropped", p.estimation_report().graph_inputs_dropped);
    j.Field("submap_origins", g.submap_origins).Field("robot_poses", g.robot_poses);
    j.Field("frame_switches", g.frame_switches).Field("factors", g.factors);
    j.Field("rejected_factors", g.rejected_factors).Field("unplaced", g.unplaced);
    j.Field("solves", g.solves).Field("reinitializations", g.reinitializations);
    j.Field("unconnected_variables", g.unconnected_variables);
    j.Field("chi2", g.chi2);
    j.Key("gnss").BeginObject();
    j.Field("fixes", g.gnss_fixes)
        .Field("factors", g.gnss_factors)
        .Field("team_factors", g.gnss_team_factors);
    j.Field("placed_subgraphs", g.gnss_placed_subgraphs).Field("refused", g.gnss_refused);
    j.Field("unplaced", g.gnss_unplaced).Field("pending", g.gnss_pending);
    // Where the datum's east-north-up frame lies in the graph's world: the map's geo-reference.
    if (Eigen::Isometry3d T_world_enu; graph->Datum(&T_world_enu)) {
      const Eigen::Vector3d t = T_world_enu.translation();
      const Eigen::Matrix3d R = T_world_enu.linear();
      j.Key("T_world_enu").BeginObject();
      j.Field("x", t.x()).Field("y", t.y()).Field("z", t.z());
      j.Field("yaw_deg", std::atan2(R(1, 0), R(0, 0)) * 180.0 / std::numbers::pi);
      j.EndObject();
    }
    j.EndObject();
    j.Key("first_errors").BeginArray();
    for (const auto& e : g.errors) j.String(e);
    j.EndArray();
    j.EndObject();
  }
  if (const SubmapMatchingStage* matching = p.matching()) {
    const SubmapMatchingReport m = matching->report();
    j.Key("matching").BeginObject();
    j.Field("submaps", m.submaps).Field("suitable", m.suitable).Field("searchable", m.searchable);
    j.Field("attempts", m.attempts).Field("matched", m.matched).Field("accepted", m.accepted);
    j.Key("pairs").BeginObject();
    for (const auto& [why, count] : m.pairs) j.Field(why, count);
    j.EndObject();
    j.Key("first_errors").BeginArray();
    for (const auto& e : m.errors) j.String(e);
    j.EndArray();
    j.EndObject();
  }
  // Planar faces and straight edges as landmarks: what was compared, paired and what the graph holds.
  std::optional<GraphStageReport> graph_report;
  if (const GraphStage* graph = p.graph()) graph_report = graph->report();
  if (const PlaneLandmarkStage* planes = p.plane_landmarks()) {
    WriteStructureLandmarks(
        j, "plane_landmarks", "faces", planes->report(),
        graph_report
            ? std::optional<GraphCounts>({graph_report->plane_landmarks, graph_report->plane_observations,
                                          graph_report->plane_observations_pending})
            : std::nullopt);
  }
  if (const LineLandmarkStage* lines = p.line_landmarks()) {
    WriteStructureLandmarks(j, "line_landmarks", "edges", lines->report(),
                            graph_report ? std::optional<GraphCounts>(
                                               {graph_report->line_landmarks, graph_report->line_observations,
                                                graph_report->line_observations_pending})
                                         : std::nullopt);
  }
  if (const RobotDetectionStage* detection = p.detection()) {
    // Tag sightings (thesis 6.2): what the detector saw, and what the graph made of them.
    const RobotDetectionReport& r = detection->report();
    j.Key("detection").BeginObject();
    j.Field("images", r.images).Field("bad_images", r.bad_images).Field("tags", r.tags);
    j.Field("full_scans", r.full_scans).Field("region_scans", r.region_scans).Field("regions", r.regions);
    j.Field("idle", r.idle).Field("tags_in_regions", r.tags_in_regions);
    j.Field("predictions", r.predictions).Field("predicted_regions", r.predicted_regions);
    j.Field("tags_in_predicted_regions", r.tags_in_predicted_regions);
    j.Field("own_tags", r.own_tags).Field("unknown_ids", r.unknown_ids).Field("pose_failures", r.pose_failures);
    j.Field("usable", r.usable).Field("refused", r.refused);
    if (const GraphStage* graph = p.graph()) {
      const GraphStageReport g = graph->report();
      j.Field("graph_detections", g.detections).Field("graph_landmark_observations", g.landmark_observations);
      j.Field("graph_pending", g.detections_pending).Field("graph_unplaced", g.detections_unplaced);
      j.Field("graph_flipped", g.detections_flipped)
          .Field("graph_against_gravity", g.detections_against_gravity);
    }
    j.Key("first_errors").BeginArray();
    for (const auto& e : r.errors) j.String(e);
    j.EndArray();
    j.EndObject();
  }
  const FaultReport f = p.fault_report();
  j.Key("faults").BeginObject();
  j.Field("total", f.total);
  j.Key("by_device").BeginObject();
  for (const auto& [device, kinds] : f.counts) {
    j.Key(device).BeginObject();
    for (const auto& [kind, n] : kinds) j.Field(kind, n);
    j.EndObject();
  }
  j.EndObject();
  j.Key("first_messages").BeginArray();
  for (const auto& m : f.first_messages) j.String(m);
  j.EndArray();
  j.EndObject();
  j.EndObject();
  return j.str();
}

std::string BuildDiagnosticsJson(const RunInfo& run, const Pipeline& p) {
  JsonWriter j;
  j.BeginObject();
  j.Field("wall_time_s", run.wall_time);
  j.Field("memory_locked", run.memory_locked);
  if (!run.memory_lock_note.empty()) j.Field("memory_lock_note", run.memory_lock_note);
  j.Key("memory").BeginObject();
  j.Field("heap_policy", run.heap_policy);
  if (!run.heap_policy_note.empty()) j.Field("heap_policy_note", run.heap_policy_note);
  j.Field("rss_mb", static_cast<double>(run.heap.rss_bytes) * 1e-6);
  j.Field("peak_rss_mb", static_cast<double>(run.heap.peak_rss_bytes) * 1e-6);
  j.Field("heap_in_use_mb", static_cast<double>(run.heap.in_use_bytes) * 1e-6);
  j.Field("heap_free_retained_mb", static_cast<double>(run.heap.free_retained_bytes) * 1e-6);
  // What grows with the mission (the map, the trajectories kept for the outputs, a simulator's
  // streams), so that the rest (queues, fixed histories, scratch) can be seen to stay bounded.
  const MappingStageReport& mapping = p.mapping_report();
  const uint64_t features = p.matching() != nullptr ? p.matching()->report().features_bytes : 0;
  uint64_t history = p.graph() != nullptr ? p.graph()->report().history_bytes : 0;
  for (const Trajectory* t : {p.trajectory(), p.odometry()}) history += t != nullptr ? HeapBytes(t->poses) : 0;
  const uint64_t map_bytes = mapping.composer_bytes + mapping.submaps_memory_bytes + features;
  j.Field("map_composer_mb", static_cast<double>(mapping.composer_bytes) * 1e-6);
  j.Field("submaps_mb", static_cast<double>(mapping.submaps_memory_bytes) * 1e-6);
  j.Field("matcher_features_mb", static_cast<double>(features) * 1e-6);
  j.Field("map_mb", static_cast<double>(map_bytes) * 1e-6);
  j.Field("trajectories_mb", static_cast<double>(history) * 1e-6);
  j.Field("simulator_mb", static_cast<double>(run.simulator_bytes) * 1e-6);
  // glibc's count; a sanitizer's allocator leaves it at zero, and then there is nothing to subtract from.
  if (run.heap.in_use_bytes > 0) {
    j.Field("heap_rest_mb", (static_cast<double>(run.heap.in_use_bytes) -
                             static_cast<double>(map_bytes + history + run.simulator_bytes)) * 1e-6);
  }
  j.EndObject();
  j.Key("executors").BeginArray();
  std::vector<ExecutorReport> executors = p.executor_reports();
  executors.insert(executors.end(), run.extra_executors.begin(), run.extra_executors.end());
  for (const ExecutorReport& e : executors) {
    j.BeginObject();
    j.Field("name", e.name);
    j.Field("realtime_requested", e.realtime_requested);
    j.Field("realtime_granted", e.realtime_granted);
    j.Field("policy", e.policy);
    j.Field("priority", e.priority);
    j.Field("cpu_seconds", e.cpu_seconds);
    if (!e.affinity_note.empty()) j.Field("note", e.affinity_note);
    j.EndObject();
  }
  j.EndArray();
  if (run.live) {
    j.Key("live_stream").BeginObject();
    j.Field("port", run.live->port).Field("published", run.live->published);
    j.Field("dropped_for_slow_clients", run.live->dropped).Field("protocol_errors", run.live->protocol_errors);
    j.Field("server_cpu_seconds", run.live->server_cpu_seconds);
    j.Field("image_codec_failures", run.image_codec_failures);
    j.EndObject();
  }
  j.Field("deadline_misses", p.deadline_misses());
  j.Key("latency").BeginArray();
  for (const LatencyReport& l : p.latency_reports()) {
    j.BeginObject();
    j.Field("stage_input", l.name).Field("count", l.count);
    j.Field("p50_s", l.p50).Field("p99_s", l.p99).Field("p999_s", l.p999).Field("max_s", l.max);
    j.Field("over_1ms", l.over_1ms);
    j.EndObject();
  }
  j.EndArray();
  // Processing time per stage and frame (medians are the figures to compare; timing depends on the
  // host, so it lives here and not in summary.json).
  j.Key("stage_timing").BeginArray();
  for (const StageTimingReport& t : p.stage_timing_reports()) {
    j.BeginObject();
    j.Field("stage", t.name).Field("count", t.count);
    j.Field("median_s", t.p50).Field("p99_s", t.p99).Field("max_s", t.max);
    j.EndObject();
  }
  j.EndArray();
  if (const SubmapMatchingStage* matching = p.matching()) {
    // The matcher pool: how long its work took and how far it fell behind.
    const SubmapMatchingReport m = matching->report();
    j.Key("matcher_pool").BeginObject();
    j.Field("jobs_waiting_max", m.jobs_waiting_max);
    j.Field("features_ms_p50", m.features_ms_p50).Field("features_ms_max", m.features_ms_max);
    j.Field("match_ms_p50", m.match_ms_p50).Field("match_ms_max", m.match_ms_max);
    j.EndObject();
  }
  if (!run.team_links.empty()) {
    // The exchange's links: bytes each way and the backlog of items the peer has not acknowledged.
    j.Key("team_links").BeginArray();
    for (const TeamLinkStatus& l : run.team_links) {
      j.BeginObject();
      j.Field("peer", l.peer).Field("sent_bytes", l.sent_bytes).Field("received_bytes", l.received_bytes);
      j.Field("queued_items", l.queued_items).Field("queued_bytes", l.queued_bytes);
      j.Field("queued_items_max", l.queued_items_max).Field("queued_bytes_max", l.queued_bytes_max);
      j.EndObject();
    }
    j.EndArray();
  }
  j.Key("queues").BeginArray();
  for (const QueueReport& q : p.queue_reports()) {
    j.BeginObject();
    j.Field("name", q.name).Field("capacity", q.capacity).Field("pushed", q.pushed);
    j.Field("dropped", q.dropped).Field("high_water", q.high_water);
    j.EndObject();
  }
  j.EndArray();
  j.EndObject();
  return j.str();
}

}  // namespace cairn
