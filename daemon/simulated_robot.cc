#include "daemon/simulated_robot.h"

#include <algorithm>
#include <sstream>

#include "sim/simulator_source.h"
#include "sim/world_file.h"

namespace cairn {
namespace {

std::vector<std::string> SplitRobots(const std::string& list) {
  std::vector<std::string> names;
  std::stringstream in(list);
  for (std::string name; std::getline(in, name, ',');) {
    name.erase(0, name.find_first_not_of(' '));
    name.erase(name.find_last_not_of(' ') + 1);
    names.push_back(name);
  }
  return names;
}

}  // namespace

Expected<std::shared_ptr<const sim::MissionSimulator>> OpenSimulatedMission(const CairndOptions& options,
                                                                            const std::string& config_path) {
  const SimSourceOptions& o = options.sim;
  sim::WorldOptions world;
  if (!o.world.empty()) {
    auto loaded = sim::LoadWorldFile(o.world);
    if (!loaded.ok()) return Status(loaded.status().code(), config_path + ": sim.world: " + loaded.status().message());
    world = *loaded;
  }
  world.seed = static_cast<uint64_t>(o.seed);

  sim::MissionOptions mission;
  mission.robots = SplitRobots(o.robots);
  mission.duration = o.duration;
  mission.image_scale = o.image_scale;
  mission.motion_blur_samples = static_cast<int>(o.motion_blur_samples);
  mission.render_threads = static_cast<int>(o.render_threads);
  mission.deploy_from_lander = o.deploy_from_lander;
  // The simulated platform controller speaks the layout this robot's decoder expects.
  mission.can = options.can;
  auto simulator = sim::MissionSimulator::Create(world, mission);
  if (!simulator.ok()) {
    return Status(simulator.status().code(), config_path + ": sim: " + simulator.status().message());
  }
  return std::shared_ptr<const sim::MissionSimulator>(std::move(*simulator));
}

Expected<TagCarrierTable> SimulatedTagCarriers(const CairndOptions& options, const std::string& config_path) {
  auto mission = OpenSimulatedMission(options, config_path);
  if (!mission.ok()) return mission.status();
  TagCarrierTable table;
  for (const sim::SimRobot& r : (*mission)->robots()) {
    for (const sim::SimMarker& m : r.markers) {
      CAIRN_RETURN_IF_ERROR(table.Add(m.id, r.name, false, m.size, m.T_body_marker));
    }
  }
  const auto& landmarks = (*mission)->landmarks();
  if (!landmarks.empty()) {
    Eigen::Vector3d centre = Eigen::Vector3d::Zero();
    for (const sim::SimMarker& m : landmarks) centre += m.T_body_marker.translation();
    centre /= static_cast<double>(landmarks.size());
    const Eigen::Isometry3d T_lander_world(Eigen::Translation3d(-centre));
    for (const sim::SimMarker& m : landmarks) {
      CAIRN_RETURN_IF_ERROR(table.Add(m.id, "lander", true, m.size, T_lander_world * m.T_body_marker));
    }
  }
  return table;
}

Expected<SimulatedRobot> OpenSimulatedRobot(const CairndOptions& options, const std::string& config_path) {
  auto mission = OpenSimulatedMission(options, config_path);
  if (!mission.ok()) return mission.status();
  std::shared_ptr<const sim::MissionSimulator> shared = std::move(*mission);
  const auto& robots = shared->robots();
  const auto it = std::find_if(robots.begin(), robots.end(),
                               [&](const sim::SimRobot& r) { return r.name == options.robot.name; });
  if (it == robots.end()) {
    return InvalidArgumentError(config_path + ": robot.name '" + options.robot.name +
                                "' is not one of sim.robots '" + options.sim.robots + "'");
  }
  const size_t index = static_cast<size_t>(it - robots.begin());

  SimulatedRobot robot;
  const sim::SimRobot& r = shared->robots()[index];
  robot.stereo = r.stereo;
  robot.imu = r.imu;
  robot.camera_rate_hz = r.camera_rate_hz;
  robot.has_wheels = r.kind == sim::SimRobotKind::kRover;
  robot.ground_truth.frame = "world";
  for (const sim::ImuTruth& s : shared->ImuStream(index)) {
    robot.ground_truth.poses.push_back({s.sample.time, s.state.T_world_body});
  }
  robot.source = std::make_unique<sim::SimulatorSource>(shared, index, options.replay, options.sim.gnss,
                                                        static_cast<uint64_t>(options.sim.seed));
  return robot;
}

}  // namespace cairn
