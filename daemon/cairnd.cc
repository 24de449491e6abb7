#include "daemon/cairnd.h"

#include <signal.h>

#include <chrono>
#include <filesystem>
#include <limits>

#include <spdlog/spdlog.h>

#include "common/atomic_file.h"
#include "common/heap_bytes.h"
#include "common/options_yaml_writer.h"
#include "daemon/comms/comms_stage.h"
#include "daemon/detections_csv.h"
#include "daemon/earlier_runs.h"
#include "daemon/heap_policy.h"
#include "daemon/pipeline/pipeline.h"
#include "daemon/run_summary.h"
#include "daemon/simulated_robot.h"
#include "daemon/submap_index.h"
#include "daemon/systemd_notifier.h"
#include "daemon/team_summary.h"
#include "drivers/aravis_stereo_camera.h"
#include "drivers/can_wheel_decoder.h"
#include "drivers/gpiod_trigger.h"
#include "drivers/iio_imu_driver.h"
#include "drivers/nmea_gnss_driver.h"
#include "drivers/replay/euroc_replay.h"
#include "drivers/replay/mcap_replay.h"
#include "drivers/socketcan_wheel_driver.h"
#include "drivers/trigger_frame_stamper.h"
#include "drivers/xsens_imu_driver.h"
#include "estimation/graph/g2o_io.h"

namespace cairn {
namespace {

const char* PacingName(ReplayPacing p) {
  switch (p) {
    case ReplayPacing::kRealTime: return "realtime";
    case ReplayPacing::kScaled: return "scaled";
    case ReplayPacing::kFastAsPossible: return "fast";
  }
  return "fast";
}

const char* RobotKindName(RobotKind k) {
  switch (k) {
    case RobotKind::kRover: return "rover";
    case RobotKind::kHexacopter: return "hexacopter";
    case RobotKind::kHandheld: return "handheld";
  }
  return "rover";
}

}  // namespace

Cairnd::Cairnd(CairndOptions options, std::string config_path)
    : options_(std::move(options)), config_path_(std::move(config_path)) {}

void Cairnd::BlockTerminationSignals() {
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  pthread_sigmask(SIG_BLOCK, &set, nullptr);
}

Status Cairnd::Prepare() {
  if (options_.can.enabled) wheel_calibration_ = CanWheelDecoder(options_.can).calibration();
  if (options_.source == SourceKind::kReplay) {
    if (options_.replay.dataset.empty()) {
      return InvalidArgumentError(config_path_ + ": replay.dataset is empty; give a dataset with --replay DIR");
    }
    if (McapReplay::IsRecording(options_.replay.dataset)) {
      auto files = McapReplay::FindRecordings(options_.replay.dataset);
      if (!files.ok()) return files.status();
      const auto out = std::filesystem::weakly_canonical(options_.output.dir);
      for (const std::string& f : *files) {
        if (options_.recording.enabled && std::filesystem::weakly_canonical(f).parent_path() == out) {
          return InvalidArgumentError(f + ": replaying a recording into its own folder with recording "
                                          "enabled would overwrite it; choose another --out");
        }
      }
      // The first file's calibration: cairnd writes the same one into every file of a recording.
      auto calibration = McapReplay::ReadCalibration(files->front());
      if (!calibration.ok()) return calibration.status();
      if (*calibration) {
        stereo_calibration_ = (*calibration)->stereo;
        imu_calibration_ = (*calibration)->imu;
        camera_rate_hz_ = (*calibration)->camera_rate_hz;
        wheel_calibration_ = (*calibration)->wheels;
      } else {
        spdlog::warn("{}: the recording carries no calibration (made by an older cairnd): its sensors replay "
                     "and are recorded again, but nothing is estimated", files->front());
      }
      sources_.push_back(std::make_unique<McapReplay>(*files, options_.replay));
    }
  }
  if (options_.source == SourceKind::kReplay && sources_.empty()) {
    auto ds = EurocDataset::Open(options_.replay.dataset);
    if (!ds.ok()) return ds.status();
    if (ds->imu().empty() && ds->stereo().empty()) {
      return DataLossError(options_.replay.dataset + ": the dataset holds no IMU samples and no stereo pairs");
    }
    dataset_ = *ds;
    stereo_calibration_ = ds->stereo_calibration();
    imu_calibration_ = ds->imu_calibration();
    camera_rate_hz_ = ds->camera_rate_hz();
    sources_.push_back(std::make_unique<EurocReplay>(*ds, options_.replay));
  }
  if (options_.source == SourceKind::kSim) {
    auto robot = OpenSimulatedRobot(options_, config_path_);
    if (!robot.ok()) return robot.status();
    stereo_calibration_ = robot->stereo;
    imu_calibration_ = robot->imu;
    camera_rate_hz_ = robot->camera_rate_hz;
    if (robot->has_wheels) {
      wheel_calibration_ = CanWheelDecoder(options_.can).calibration();
    } else {
      wheel_calibration_.reset();
    }
    ground_truth_ = std::move(robot->ground_truth);
    sources_.push_back(std::move(robot->source));
  }
  // The CAN bus is a live device: a replay takes wheel odometry from its recording and a simulated
  // robot from the simulator (through the same CAN decoder), never from the bus.
  if (options_.can.enabled && options_.source == SourceKind::kLive) {
    sources_.push_back(std::make_unique<SocketCanWheelDriver>(options_.can));
  }
  // So is the IMU; a port that is absent at start is reported and retried by the driver.
  if (options_.imu.enabled && options_.source == SourceKind::kLive) {
    imu_calibration_ = options_.imu.Calibration();
    if (options_.imu.driver == ImuDriverKind::kIio) {
      sources_.push_back(std::make_unique<IioImuDriver>(options_.imu.iio, *imu_calibration_));
    } else {
      sources_.push_back(std::make_unique<XsensImuDriver>(options_.imu.xsens, *imu_calibration_));
    }
  }
  // And the cameras: absent ones are reported and retried by the driver, the rest runs meanwhile.
  if (options_.cameras.enabled && options_.source == SourceKind::kLive) {
    stereo_calibration_ = options_.cameras.Calibration();
    camera_rate_hz_ = options_.cameras.aravis.frame_rate_hz;
    sources_.push_back(std::make_unique<AravisStereoCamera>(options_.cameras.aravis, *stereo_calibration_));
    camera_source_ = sources_.back().get();
  }
  // And the cameras' trigger line, likewise reported and retried while its chip is absent.
  if (options_.trigger.driver == TriggerDriverKind::kGpiod && options_.source == SourceKind::kLive) {
    sources_.push_back(std::make_unique<GpiodTrigger>(options_.trigger.gpiod));
    trigger_source_ = sources_.back().get();
  }
  // And the GNSS receiver, likewise.
  if (options_.gnss.driver == GnssDriverKind::kNmea && options_.source == SourceKind::kLive) {
    sources_.push_back(std::make_unique<NmeaGnssDriver>(options_.gnss.nmea));
  }
  const bool fixes_come =
      (options_.source == SourceKind::kLive && options_.gnss.driver != GnssDriverKind::kNone) ||
      (options_.source == SourceKind::kSim && options_.sim.gnss.enabled);
  const bool fixes_used = options_.graph.enabled && options_.graph.gnss.enabled;
  if (fixes_come != fixes_used) {
    spdlog::warn("{}: {}", config_path_,
                 fixes_come
                     ? "GNSS fixes come (gnss.driver or sim.gnss.enabled) but graph.gnss.enabled is false: "
                       "they are not used"
                     : "graph.gnss.enabled but no GNSS source (gnss.driver for live, sim.gnss.enabled): "
                       "the graph gets no fixes");
  }
  if (options_.source == SourceKind::kLive && !options_.cameras.enabled) {
    // Say what a live robot lacks, once, before it runs without it.
    spdlog::warn("{}: cameras.enabled is false: this live run records and streams the IMU and wheels, "
                 "estimation and mapping wait for cameras",
                 config_path_);
  }
  if (sources_.empty()) {
    return InvalidArgumentError(config_path_ +
                                ": no sensor source is enabled (replay, the simulator, or for source: live "
                                "cameras.enabled, imu.enabled, can.enabled, trigger.driver)");
  }
  // Only once the sources are good: a start that fails moves nothing.
  KeepEarlierRun();
  // Fail before any work if the output folder cannot be made.
  std::error_code ec;
  std::filesystem::create_directories(options_.output.dir, ec);
  if (ec) return IoError(options_.output.dir + ": cannot create the output folder: " + ec.message());
  return Status::Ok();
}

void Cairnd::KeepEarlierRun() {
  const std::string& dir = options_.output.dir;
  std::error_code ec;
  if (options_.source == SourceKind::kReplay &&
      std::filesystem::weakly_canonical(options_.replay.dataset, ec) == std::filesystem::weakly_canonical(dir, ec)) {
    spdlog::warn("{}: replaying from the output folder itself; outputs of an earlier run there are overwritten", dir);
    return;
  }
  std::vector<std::string> persistent = {options_.team.store_dir.empty() ? dir + "/exchange" : options_.team.store_dir,
                                         options_.team.members_file, options_.team.secret_key_file, config_path_};
  if (options_.source == SourceKind::kReplay) persistent.push_back(options_.replay.dataset);
  const auto kept = EarlierRuns::Keep(dir, options_.output.keep_runs, persistent);
  // Not being able to keep them must not keep the robot from running: say so and go on.
  if (!kept.ok()) {
    spdlog::error("earlier run's outputs: {}; they may be overwritten", kept.status().ToString());
    return;
  }
  if (!kept->kept_in.empty()) {
    spdlog::warn("{} outputs of an earlier run moved to {} (a restart never overwrites them)", kept->moved_entries,
                 kept->kept_in);
  } else if (kept->moved_entries > 0) {
    spdlog::info("{} outputs of an earlier run removed (output.keep_runs is 0)", kept->moved_entries);
  }
  if (kept->removed_runs > 0) {
    spdlog::info("{} oldest earlier runs removed to keep {} (output.keep_runs)", kept->removed_runs,
                 options_.output.keep_runs);
  }
}

int Cairnd::Run() {
  const auto wall_start = std::chrono::steady_clock::now();
  RunInfo run;
  run.robot = options_.robot.name;
  run.mode = options_.source == SourceKind::kReplay ? "replay" : options_.source == SourceKind::kSim ? "sim" : "live";

  run.heap_policy = HeapPolicy::Apply(&run.heap_policy_note);
  const ExecutorsOptions& ex = options_.executors;
  if (ex.estimation.realtime || ex.stereo.realtime || ex.mapping.realtime || ex.telemetry.realtime) {
    run.memory_locked = Executor::LockProcessMemory(&run.memory_lock_note);
  }

  PipelineRates rates;
  if (imu_calibration_) rates.imu_hz = imu_calibration_->rate_hz;
  rates.camera_hz = camera_rate_hz_;
  // Replayed and simulated sources share the replay section's pacing.
  const bool deterministic = options_.source != SourceKind::kLive && options_.replay.deterministic;
  Pipeline pipeline(options_.executors, options_.queues, rates, deterministic);
  if (stereo_calibration_ && imu_calibration_) {
    // The estimation chain needs the camera and IMU calibration the dataset or simulator carries.
    EstimationSetup setup;
    setup.imu = *imu_calibration_;
    setup.stereo = *stereo_calibration_;
    if (wheel_calibration_) setup.wheels = *wheel_calibration_;
    setup.filter = options_.filter;
    setup.vo = options_.vo;
    setup.frame_switch = options_.frame_switch;
    // With mapping, submap partitioning decides when the frame switches.
    if (options_.mapping.enabled) setup.frame_switch.enabled = false;
    if (Status s = pipeline.EnableEstimation(setup); !s.ok()) {
      spdlog::error("{}: {}", options_.source == SourceKind::kSim ? "sim" : options_.replay.dataset, s.ToString());
      return 1;
    }
    if (options_.graph.enabled && options_.vo.enabled) {
      if (Status s = pipeline.EnableGraph(options_.graph); !s.ok()) {
        spdlog::error("{}: {}", config_path_, s.ToString());
        return 1;
      }
    }
    if (options_.mapping.enabled && options_.vo.enabled) {
      MappingSetup mapping;
      mapping.robot = options_.robot.name;
      mapping.stereo = options_.stereo;
      mapping.mapping = options_.mapping;
      mapping.output_dir = options_.output.dir;
      if (Status s = pipeline.EnableMapping(mapping); !s.ok()) {
        spdlog::error("{}: {}", config_path_, s.ToString());
        return 1;
      }
      if (options_.matching.enabled) {
        if (Status s = pipeline.EnableMatching(options_.matching, options_.robot.name); !s.ok()) {
          spdlog::error("{}: {}", config_path_, s.ToString());
          return 1;
        }
      }
    }
    const bool no_carriers = options_.detection.carriers_file.empty() && options_.source != SourceKind::kSim;
    if (options_.detection.enabled && no_carriers) {
      // A recording says nothing about the team's tags, and a robot must be told which tag is on
      // which teammate: without that file it runs everything but detection.
      spdlog::warn("{}: detection.carriers_file is empty (which tag is on which robot): robot detection is off "
                   "for this {} run",
                   config_path_, options_.source == SourceKind::kReplay ? "replay" : "live");
    } else if (options_.detection.enabled) {
      Expected<TagCarrierTable> table = options_.detection.carriers_file.empty()
                                            ? SimulatedTagCarriers(options_, config_path_)
                                            : TagCarrierTable::Load(options_.detection.carriers_file);
      // A relative error table is the profile's: configs/detection/ beside it, installed or not.
      const auto resolve = [&](const std::string& name) {
        std::filesystem::path path = name;
        if (!path.empty() && path.is_relative()) path = std::filesystem::path(config_path_).parent_path() / path;
        return path.string();
      };
      Status s = table.ok() ? pipeline.EnableDetection(options_.detection, std::move(*table), options_.robot.name,
                                                       resolve(options_.detection.error_table),
                                                       resolve(options_.detection.region_error_table))
                            : table.status();
      if (!s.ok()) {
        spdlog::error("{}: detection: {}", config_path_, s.ToString());
        return 1;
      }
    }
  }
  std::unique_ptr<CommsStage> comms;
  if (options_.team.enabled) {
    if (pipeline.graph() == nullptr) {
      spdlog::error("{}: team.enabled needs the graph (graph.enabled, vo.enabled and a calibrated source)", config_path_);
      return 1;
    }
    CommsSetup setup;
    setup.team = options_.team;
    setup.robot = options_.robot.name;
    setup.robot_kind = RobotKindName(options_.robot.kind);
    setup.output_dir = options_.output.dir;
    setup.executor = options_.executors.comms;
    auto stage = CommsStage::Create(setup);
    if (!stage.ok()) {
      spdlog::error("team exchange: {}", stage.status().ToString());
      return 1;
    }
    comms = std::move(*stage);
    std::map<char, std::string> names;
    for (const TeamMember& m : comms->team().members) names[m.letter[0]] = m.name;
    if (Status s = pipeline.SetTeamLink(comms.get(), names); !s.ok()) {
      spdlog::error("{}: {}", config_path_, s.ToString());
      return 1;
    }
    if (comms->letter() != options_.graph.optimizer.own_robot) {
      spdlog::error("{}: graph.optimizer.own_robot '{}' is not the letter {} gives '{}' ('{}')", config_path_,
                    options_.graph.optimizer.own_robot, comms->team().path, options_.robot.name, comms->letter());
      return 1;
    }
    comms->Start();
    spdlog::info("team exchange: {} teammates in {}", comms->team().members.size() - 1, comms->team().path);
  }
  std::unique_ptr<TelemetryStage> telemetry;
  if (options_.recording.enabled || options_.live.enabled) {
    telemetry = std::make_unique<TelemetryStage>(options_.executors.telemetry,
                                                 static_cast<size_t>(options_.queues.telemetry), deterministic);
    if (options_.recording.enabled) {
      std::string calibration;
      if (stereo_calibration_ && imu_calibration_) {
        RecordedCalibration c;
        c.robot = options_.robot.name;
        c.stereo = *stereo_calibration_;
        c.camera_rate_hz = camera_rate_hz_;
        c.imu = *imu_calibration_;
        c.wheels = wheel_calibration_;
        calibration = c.Encode();
      }
      telemetry->EnableRecording(options_.output.dir, options_.recording, std::move(calibration));
    }
    if (options_.live.enabled) {
      if (Status s = telemetry->EnableLiveStream(options_.robot.name, options_.live); !s.ok()) {
        // Degrade: no live view, everything else runs.
        spdlog::error("{}", s.ToString());
      } else {
        spdlog::info("live stream (Foxglove WebSocket) on ws://{}:{}", options_.live.address,
                     telemetry->live_report().port);
      }
    }
    telemetry->Start();
    pipeline.SetTelemetry(telemetry.get());
  }
  pipeline.Start();
  // Everything the system refused of the requested scheduling, in one warning.
  std::string refused;
  if ((ex.estimation.realtime || ex.stereo.realtime || ex.mapping.realtime || ex.telemetry.realtime) && !run.memory_locked) {
    refused = "memory not locked (" + run.memory_lock_note + ")";
  }
  for (const ExecutorReport& e : pipeline.executor_reports()) {
    if (e.affinity_note.empty()) continue;
    refused += (refused.empty() ? "" : "; ") + e.name +
               (e.realtime_requested && !e.realtime_granted ? " runs at normal priority: " : ": ") +
               e.affinity_note;
  }
  if (!refused.empty()) spdlog::warn("real-time scheduling degraded: {}", refused);

  // With a trigger line, the live cameras' frames take their edges' times on their way in.
  std::unique_ptr<TriggerFrameStamper> stamper;
  if (camera_source_ != nullptr && trigger_source_ != nullptr) {
    stamper = std::make_unique<TriggerFrameStamper>(options_.trigger.stamping, &pipeline,
                                                    trigger_source_->name() + "/stamping");
  }
  for (auto& source : sources_) {
    const bool stamped = stamper && (source.get() == camera_source_ || source.get() == trigger_source_);
    if (Status s = source->Start(stamped ? static_cast<SensorSink*>(stamper.get()) : &pipeline); !s.ok()) {
      spdlog::error("source '{}' did not start: {}", source->name(), s.ToString());
    }
  }

  SystemdNotifier notifier;
  notifier.Ready("running " + run.mode);
  spdlog::info("cairnd '{}' running ({}{})", run.robot, run.mode,
               deterministic ? ", deterministic" : "");

  const bool finite = options_.source != SourceKind::kLive;  // replays and simulations end
  sigset_t set;
  sigemptyset(&set);
  sigaddset(&set, SIGTERM);
  sigaddset(&set, SIGINT);
  auto next_status = std::chrono::steady_clock::now();
  const auto status_period = std::chrono::duration<double>(options_.daemon.status_interval);
  while (true) {
    timespec timeout{0, 50 * 1000 * 1000};
    const int sig = sigtimedwait(&set, nullptr, &timeout);
    if (sig == SIGTERM || sig == SIGINT) {
      run.stop_reason = "signal";
      spdlog::info("{} received: stopping", sig == SIGTERM ? "SIGTERM" : "SIGINT");
      break;
    }
    if (finite) {
      bool all_done = true;
      for (const auto& s : sources_) all_done = all_done && s->finished();
      if (all_done) {
        run.stop_reason = "end_of_data";
        break;
      }
    }
    notifier.KeepAlive();
    if (std::chrono::steady_clock::now() >= next_status) {
      next_status += std::chrono::duration_cast<std::chrono::steady_clock::duration>(status_period);
      const std::string status = "imu " + std::to_string(pipeline.consumed_imu()) + ", stereo " +
                                 std::to_string(pipeline.consumed_stereo()) + ", dropped " +
                                 std::to_string(pipeline.total_dropped()) + ", deadline misses " +
                                 std::to_string(pipeline.deadline_misses()) + ", faults " +
                                 std::to_string(pipeline.fault_report().total) +
                                 (comms ? "; team: " + comms->LinkSummary() : std::string());
      if (telemetry) telemetry->PublishDiagnostics(status);
      notifier.Status(status);
      spdlog::debug("{}", status);
    }
  }

  notifier.Stopping();
  for (auto& s : sources_) s->Stop();
  if (stamper) run.trigger_stamping = stamper->counts();
  // With a team: lingers until the teammates hold the same logs; after a stop signal briefly, and
  // a second signal ends it.
  const bool signalled = run.stop_reason == "signal";
  pipeline.StopAndDrain(
      signalled ? options_.team.stop_linger : std::numeric_limits<double>::infinity(), [&set] {
        timespec now{0, 0};
        const int sig = sigtimedwait(&set, nullptr, &now);
        if (sig != SIGTERM && sig != SIGINT) return false;
        spdlog::warn("{} received again: ending the team's linger", sig == SIGTERM ? "SIGTERM" : "SIGINT");
        return true;
      });
  if (comms) {
    comms->Stop();
    run.extra_executors.push_back(comms->executor_report());
    run.team_links = comms->report().links;
  }
  if (telemetry) {
    telemetry->StopAndDrain();
    if (telemetry->recording()) run.recording = telemetry->recording_report();
    if (options_.live.enabled) run.live = telemetry->live_report();
    run.telemetry_dropped = telemetry->dropped();
    run.image_codec_failures = telemetry->image_codec_failures();
    run.extra_executors.push_back(telemetry->executor_report());
  }
  run.complete = finite && run.stop_reason == "end_of_data";
  run.heap = HeapPolicy::Measure();
  for (const auto& source : sources_) run.simulator_bytes += source->memory_bytes();
  if (ground_truth_) run.simulator_bytes += HeapBytes(ground_truth_->poses);
  run.wall_time = std::chrono::duration<double>(std::chrono::steady_clock::now() - wall_start).count();
  if (dataset_) {
    run.replay = ReplayInfo{options_.replay.dataset, PacingName(options_.replay.pacing),
                            deterministic, dataset_->stereo().size(), dataset_->unpaired_left(),
                            dataset_->unpaired_right(), dataset_->imu().size()};
  }
  if (Status s = WriteOutputs(run, pipeline, comms.get()); !s.ok()) {
    spdlog::error("writing outputs failed: {}", s.ToString());
    return 1;
  }
  spdlog::info("{}: imu {} samples, stereo {} frames, wheel {} samples, {} dropped, {} faults -> {}/summary.json",
               run.stop_reason, pipeline.imu_stats().count(), pipeline.stereo_stats().count(),
               pipeline.wheel_stats().count(), pipeline.total_dropped(),
               pipeline.fault_report().total, options_.output.dir);
  return 0;
}

Status Cairnd::WriteTrajectory(const std::string& stem, const Trajectory& trajectory) const {
  for (const std::string& name : options_.output.TrajectoryFormatList()) {
    if (name == "tum") {
      CAIRN_RETURN_IF_ERROR(WriteFileAtomically(stem + ".tum", TrajectoryIo::Format(trajectory, TrajectoryFormat::kTum)));
    } else if (name == "euroc") {
      CAIRN_RETURN_IF_ERROR(
          WriteFileAtomically(stem + ".csv", TrajectoryIo::Format(trajectory, TrajectoryFormat::kEurocCsv)));
    } else {
      CAIRN_RETURN_IF_ERROR(
          WriteFileAtomically(stem + ".kitti", TrajectoryIo::Format(trajectory, TrajectoryFormat::kKitti)));
      CAIRN_RETURN_IF_ERROR(WriteFileAtomically(stem + "_times.txt", TrajectoryIo::KittiTimes(trajectory)));
    }
  }
  return Status::Ok();
}

Status Cairnd::WriteOutputs(const RunInfo& run, const Pipeline& pipeline, const CommsStage* comms) {
  const std::string dir = options_.output.dir;
  CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/config.yaml", "# effective configuration of this run (from " +
                                                                      config_path_ + ")\n" +
                                                                      OptionsYamlWriter::Write(options_)));
  CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/diagnostics.json", BuildDiagnosticsJson(run, pipeline)));
  if (ground_truth_) {
    CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/ground_truth.tum",
                                              TrajectoryIo::Format(*ground_truth_, TrajectoryFormat::kTum)));
  }
  if (pipeline.trajectory() != nullptr) {
    // Body pose per camera frame: the filter's, chained through its frame switches into the
    // first local frame; and the raw odometry chain.
    CAIRN_RETURN_IF_ERROR(WriteTrajectory(dir + "/trajectory", *pipeline.trajectory()));
    CAIRN_RETURN_IF_ERROR(
        WriteFileAtomically(dir + "/vo.tum", TrajectoryIo::Format(*pipeline.odometry(), TrajectoryFormat::kTum)));
  }
  if (const GraphStage* graph = pipeline.graph()) {
    // The same estimates placed by the graph's optimized submap origins.
    CAIRN_RETURN_IF_ERROR(WriteTrajectory(dir + "/global_trajectory", graph->GlobalTrajectory()));
    if (comms != nullptr) {
      // Every robot the graph has tied to this one's frame, in it (eq. 4.6); the others have no
      // global trajectory here (team.json says so).
      for (const TeamMember& m : comms->team().members) {
        const char letter = m.letter[0];
        const std::vector<uint32_t> runs = graph->Runs(letter);
        for (uint32_t robot_run : runs) {
          // The latest run under the robot's name; runs before a restart by their incarnation.
          const Trajectory t = graph->GlobalTrajectory(letter, robot_run);
          const std::string name = m.name + (robot_run == runs.back() ? "" : EarlierRunSuffix(robot_run));
          if (!t.poses.empty()) CAIRN_RETURN_IF_ERROR(WriteTrajectory(dir + "/global_trajectory_" + name, t));
        }
      }
      TeamReport team_report = comms->report();
      team_report.linger_seconds = pipeline.linger().seconds;
      team_report.linger_ended = pipeline.linger().ended;
      CAIRN_RETURN_IF_ERROR(
          WriteFileAtomically(dir + "/team.json", BuildTeamJson(team_report, comms->team(), graph)));
    }
    if (options_.graph.write_g2o) {
      CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/graph.g2o", FormatG2o(graph->ExportPoseGraph())));
    }
  }
  if (const SubmapMatchingStage* matching = pipeline.matching(); matching != nullptr && options_.matching.write_csv) {
    CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/matches.csv", matching->FormatCsv()));
  }
  if (const PlaneLandmarkStage* planes = pipeline.plane_landmarks();
      planes != nullptr && pipeline.graph() != nullptr && options_.matching.plane_landmarks.write_csv) {
    CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/planes.csv", planes->Csv(*pipeline.graph())));
  }
  if (const LineLandmarkStage* lines = pipeline.line_landmarks();
      lines != nullptr && pipeline.graph() != nullptr && options_.matching.line_landmarks.write_csv) {
    CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/lines.csv", lines->Csv(*pipeline.graph())));
  }
  if (pipeline.detection() != nullptr && pipeline.graph() != nullptr && options_.detection.write_csv) {
    CAIRN_RETURN_IF_ERROR(WriteFileAtomically(dir + "/detections.csv", FormatDetectionsCsv(pipeline.graph()->detections())));
  }
  if (pipeline.mapping_enabled() && options_.mapping.write_submaps) {
    CAIRN_RETURN_IF_ERROR(WriteFileAtomically(
        dir + "/submaps/index.csv",
        FormatSubmapIndex(options_.robot.name, pipeline.submap_origin_times(), ground_truth_ ? &*ground_truth_ : nullptr)));
  }
  // Last: its presence means the run's outputs are complete.
  return WriteFileAtomically(dir + "/summary.json", BuildSummaryJson(run, pipeline));
}

}  // namespace cairn
