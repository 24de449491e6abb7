#pragma once
// The daemon process: builds the sources a configuration asks for, runs the pipeline on its
// executors, reacts to SIGTERM/SIGINT and end of data, and writes the run's outputs.

#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "daemon/cairnd_options.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimation/eval/trajectory.h"
#include "hal/calibration.h"
#include "hal/sensor_source_interface.h"

namespace cairn {

class Cairnd {
 public:
  Cairnd(CairndOptions options, std::string config_path);

  // Opens every source and validates its data. Nothing is written before this succeeds; at its
  // end an earlier run's outputs in the output folder move to earlier-runs/ (EarlierRuns).
  Status Prepare();
  // Runs until end of data or a termination signal; returns the process exit code. The caller
  // must have blocked SIGTERM and SIGINT in all threads (BlockTerminationSignals) first.
  int Run();

  static void BlockTerminationSignals();

 private:
  // Moves an earlier run's outputs aside (EarlierRuns); a failure is logged, never fatal.
  void KeepEarlierRun();
  Status WriteOutputs(const struct RunInfo& run, const class Pipeline& pipeline, const class CommsStage* comms);
  // `stem` + .tum / .csv / .kitti (+ _times.txt), for each of output.trajectory_formats.
  Status WriteTrajectory(const std::string& stem, const Trajectory& trajectory) const;

  CairndOptions options_;
  std::string config_path_;
  std::optional<EurocDataset> dataset_;
  // The sensors' calibration where the source knows it (replayed datasets, the simulator).
  std::optional<StereoCalibration> stereo_calibration_;
  std::optional<ImuCalibration> imu_calibration_;
  double camera_rate_hz_ = 0.0;
  // Where wheels are known: the configured CAN layout's contact points (a bus, a simulated rover),
  // or the recorded ones when a recording carries its calibration.
  std::optional<WheelCalibration> wheel_calibration_;
  // Simulated runs: the robot's true trajectory, written as ground_truth.tum for evaluation.
  std::optional<Trajectory> ground_truth_;
  std::vector<std::unique_ptr<SensorSourceInterface>> sources_;
  // The live cameras and their trigger line, among sources_: with both, Run() starts them into a
  // TriggerFrameStamper in front of the pipeline.
  SensorSourceInterface* camera_source_ = nullptr;
  SensorSourceInterface* trigger_source_ = nullptr;
};

}  // namespace cairn
