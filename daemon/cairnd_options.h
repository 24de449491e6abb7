#pragma once
// Everything cairnd reads from its YAML configuration. Every key is required (a shipped profile is
// complete and explicit); `cairn config doc` prints them all with units and ranges.

#include <cctype>
#include <string>

#include "daemon/dense_stereo_options.h"
#include "daemon/executor_options.h"
#include "daemon/live_stream_options.h"
#include "daemon/mapping_stage_options.h"
#include "daemon/recording_options.h"
#include "daemon/sim_source_options.h"
#include "drivers/can_wheel_options.h"
#include "drivers/replay_options.h"
#include "estimation/filter_options.h"
#include "estimation/vo_options.h"
#include "hal/options_visitor.h"

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

  void Visit(OptionsVisitor& v) { v.Text("dir", dir); }
  Status Validate() const {
    return dir.empty() ? InvalidArgumentError("dir must not be empty") : Status::Ok();
  }
};

struct CairndOptions {
  RobotOptions robot;
  SourceKind source = SourceKind::kReplay;
  ReplayOptions replay;
  SimSourceOptions sim;
  CanWheelOptions can;
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

  void Visit(OptionsVisitor& v) {
    v.Section("robot", robot);
    v.Choice("source", source,
             {{"replay", SourceKind::kReplay}, {"live", SourceKind::kLive}, {"sim", SourceKind::kSim}});
    v.Section("replay", replay);
    v.Section("sim", sim);
    v.Section("can", can);
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
  }
};

}  // namespace cairn
