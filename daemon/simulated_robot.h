#pragma once
// `source: sim`: builds the simulated mission a configuration describes and the sensor source of
// the robot this daemon plays, with its true calibration and ground-truth trajectory.

#include <memory>
#include <string>

#include "daemon/cairnd_options.h"
#include "detection/tag_carrier_table.h"
#include "estimation/eval/trajectory.h"
#include "hal/calibration.h"
#include "hal/sensor_source_interface.h"
#include "sim/mission_simulator.h"

namespace cairn {

struct SimulatedRobot {
  std::unique_ptr<SensorSourceInterface> source;
  StereoCalibration stereo;
  ImuCalibration imu;
  double camera_rate_hz = 0.0;
  bool has_wheels = false;  // its wheel CAN frames use the configured CAN layout
  Trajectory ground_truth;  // T_world_body at every IMU sample, frame "world"
};

// The whole mission the `sim:` section describes (world, robots, duration), as the daemon plays
// it; for scoring outputs against the world too. Errors name `config_path` and the key.
Expected<std::shared_ptr<const sim::MissionSimulator>> OpenSimulatedMission(const CairndOptions& options,
                                                                            const std::string& config_path);

// Every tag of the simulated mission: the robots' (by name) and the lander's (landmark "lander",
// its frame at the centre of its tags, axes of the world).
Expected<TagCarrierTable> SimulatedTagCarriers(const CairndOptions& options, const std::string& config_path);

// Errors name `config_path` and the offending key (sim.world, sim.robots, robot.name).
Expected<SimulatedRobot> OpenSimulatedRobot(const CairndOptions& options, const std::string& config_path);

}  // namespace cairn
