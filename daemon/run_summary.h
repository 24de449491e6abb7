#pragma once
// What a run leaves behind. summary.json holds only what follows from the data (so deterministic
// replays produce identical files); diagnostics.json holds what depends on the host and timing
// (scheduling granted, queue high-water marks, wall time).

#include <optional>
#include <string>

#include "daemon/comms/team_link_status.h"
#include "daemon/heap_policy.h"
#include "daemon/pipeline/pipeline.h"
#include "daemon/pipeline/telemetry_stage.h"
#include "drivers/trigger_frame_stamper.h"

namespace cairn {

struct ReplayInfo {
  std::string dataset;
  std::string pacing;
  bool deterministic = false;
  size_t stereo_pairs = 0;
  int unpaired_left = 0;
  int unpaired_right = 0;
  size_t imu_samples = 0;
};

struct RunInfo {
  std::string robot;
  std::string mode;         // "replay" or "live"
  std::string stop_reason;  // "end_of_data" or "signal"
  bool complete = false;    // all input consumed (replay) 
  std::optional<ReplayInfo> replay;
  std::optional<RecordingReport> recording;
  std::optional<LiveStreamReport> live;
  // Live cameras on a trigger line: how their frames found their edges.
  std::optional<TriggerFrameStamperCounts> trigger_stamping;
  uint64_t telemetry_dropped = 0;
  uint64_t image_codec_failures = 0;  // images the PNG/JPEG encoder refused (recording or live)
  std::vector<ExecutorReport> extra_executors;  // executors outside the pipeline (telemetry, comms)
  std::vector<TeamLinkStatus> team_links;       // with a team: each link at the end
  double wall_time = 0.0;   // s
  bool memory_locked = false;
  std::string memory_lock_note;
  bool heap_policy = false;  // HeapPolicy applied
  std::string heap_policy_note;
  HeapUse heap;              // at the end of the run
  // Held for the whole run by what is not the robot: the simulator's streams and ground truth.
  uint64_t simulator_bytes = 0;
};

std::string BuildSummaryJson(const RunInfo& run, const Pipeline& pipeline);
std::string BuildDiagnosticsJson(const RunInfo& run, const Pipeline& pipeline);

}  // namespace cairn
