#pragma once
// Everything cairnd reads from its YAML configuration. Every key is required (a shipped profile is
// complete and explicit); `cairn config doc` prints them all with units and ranges.

#include <algorithm>
#include <cctype>
#include <string>
#include <vector>

#include "common/options_visitor.h"
#include "daemon/comms/team_options.h"
#include "daemon/pipeline/dense_stereo_options.h"
#include "daemon/pipeline/executor_options.h"
#include "daemon/pipeline/graph_stage_options.h"
#include "daemon/pipeline/mapping_stage_options.h"
#include "daemon/pipeline/robot_detection_options.h"
#include "daemon/pipeline/submap_matching_options.h"
#include "daemon/telemetry/live_stream_options.h"
#include "daemon/telemetry/recording_options.h"
#include "drivers/camera_device_options.h"
#include "drivers/can_wheel_options.h"
#include "drivers/gnss_device_options.h"
#include "drivers/imu_device_options.h"
#include "drivers/replay/replay_options.h"
#include "drivers/trigger_device_options.h"
#include "estimation/filter/filter_options.h"
#include "estimation/vo/vo_options.h"
#include "sim/sim_source_options.h"

namespace cairn {

enum class RobotKind { kRover, kHexacopter, kHandheld };
enum class SourceKind { kReplay, kLive, kSim };

struct RobotOptions {
  std::string name = "robot";
  RobotKind kind = RobotKind::kRover;

  void Visit(OptionsVisitor& v) {
    v.Text("name", name);
    v.Choice("kind", kind, {{"rover", RobotKind::kRover},
                            {"hexacopter", RobotKind::kHexacopter},
                            {"handheld", RobotKind::kHandheld}});
  }
  Status Validate() const {
    if (name.empty()) return InvalidArgumentError("name must not be empty");
    for (char c : name) {
      if (!(std::isalnum(static_cast<unsigned char>(c)) || c == '-' || c == '_')) {
        return InvalidArgumentError("name '" + name + "' may only hold letters, digits, '-' and '_'");
      }
    }
    return Status::Ok();
  }
};

struct DaemonOptions {
  // How often the daemon reports progress (log line and systemd STATUS).
  double status_interval = 1.0;

  void Visit(OptionsVisitor& v) { v.Number("status_interval", status_interval, 0.05, 3600.0, "s"); }
};

struct OutputOptions {
  // Where summary.json and the other run outputs go; --out overrides it.
  std::string dir = "out";
  // Trajectory files, comma separated: tum (.tum), euroc (.csv, EuRoC ground-truth columns),
  // kitti (.kitti, 3x4 matrices, with _times.txt).
  std::string trajectory_formats = "tum";
  // Outputs a run finds in `dir` from the run before (a restart after a crash) move to
  // dir/earlier-runs/N; this many such folders stay, the oldest go (0: none are kept).
  int keep_runs = 10;

  void Visit(OptionsVisitor& v) {
    v.Text("dir", dir);
    v.Text("trajectory_formats", trajectory_formats);
    v.Integer("keep_runs", keep_runs, 0, 1000, "runs");
  }
  Status Validate() const {
    if (dir.empty()) return InvalidArgumentError("dir must not be empty");
    if (TrajectoryFormatList().empty()) {
      return InvalidArgumentError("trajectory_formats: '" + trajectory_formats +
                                  "' names none of tum, euroc, kitti (comma separated)");
    }
    return Status::Ok();
  }
  // The formats asked for, in order; empty when any name is unknown.
  std::vector<std::string> TrajectoryFormatList() const {
    std::vector<std::string> out;
    size_t start = 0;
    while (start <= trajectory_formats.size()) {
      size_t end = trajectory_formats.find(',', start);
      if (end == std::string::npos) end = trajectory_formats.size();
      std::string name = trajectory_formats.substr(start, end - start);
      name.erase(0, name.find_first_not_of(' '));
      name.erase(name.find_last_not_of(' ') + 1);
      if (name != "tum" && name != "euroc" && name != "kitti") return {};
      if (std::find(out.begin(), out.end(), name) == out.end()) out.push_back(name);
      start = end + 1;
    }
    return out;
  }
};

struct CairndOptions {
  RobotOptions robot;
  SourceKind source = SourceKind::kReplay;
  ReplayOptions replay;
  SimSourceOptions sim;
  CanWheelOptions can;
  ImuDeviceOptions imu;
  CameraDeviceOptions cameras;
  TriggerDeviceOptions trigger;
  GnssDeviceOptions gnss;
  ExecutorsOptions executors;
  QueueOptions queues;
  DaemonOptions daemon;
  OutputOptions output;
  RecordingOptions recording;
  LiveStreamOptions live;
  FilterOptions filter;
  VoOptions vo;
  FrameSwitchOptions frame_switch;
  DenseStereoOptions stereo;
  MappingStageOptions mapping;
  GraphStageOptions graph;
  SubmapMatchingOptions matching;
  RobotDetectionOptions detection;
  TeamOptions team;

  void Visit(OptionsVisitor& v) {
    v.Section("robot", robot);
    v.Choice("source", source,
             {{"replay", SourceKind::kReplay}, {"live", SourceKind::kLive}, {"sim", SourceKind::kSim}});
    v.Section("replay", replay);
    v.Section("sim", sim);
    v.Section("can", can);
    v.Section("imu", imu);
    v.Section("cameras", cameras);
    v.Section("trigger", trigger);
    v.Section("gnss", gnss);
    v.Section("executors", executors);
    v.Section("queues", queues);
    v.Section("daemon", daemon);
    v.Section("output", output);
    v.Section("recording", recording);
    v.Section("live", live);
    v.Section("filter", filter);
    v.Section("vo", vo);
    v.Section("frame_switch", frame_switch);
    v.Section("stereo", stereo);
    v.Section("mapping", mapping);
    v.Section("graph", graph);
    v.Section("matching", matching);
    v.Section("detection", detection);
    v.Section("team", team);
  }
};

}  // namespace cairn
