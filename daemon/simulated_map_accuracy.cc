#include "daemon/simulated_map_accuracy.h"

#include <filesystem>
#include <iostream>

#include <octomap/OcTree.h>

#include "daemon/cairnd_config.h"
#include "daemon/simulated_robot.h"
#include "sim/surface_distance.h"

namespace cairn {

Expected<SimulatedMapAccuracy> ScoreSimulatedMap(const std::string& dir, const Eigen::Isometry3d& T_world_map) {
  const std::string map_path = dir + "/map.bt", config_path = dir + "/config.yaml";
  for (const std::string& p : {map_path, config_path}) {
    if (!std::filesystem::exists(p)) return NotFoundError(p + ": missing");
  }
  SimulatedMapAccuracy a;
  // An earlier version may have written the config: the world and robots are what matter here.
  auto options = LoadEarlierRunOptions(config_path, &a.config_notes);
  if (!options.ok()) return options.status();
  auto mission = OpenSimulatedMission(*options, config_path);
  if (!mission.ok()) return mission.status();
  octomap::OcTree tree(0.1);
  // The library announces every file it reads on std::cerr; a failure is reported instead.
  std::streambuf* const cerr_buffer = std::cerr.rdbuf(nullptr);
  const bool read = tree.readBinary(map_path);
  std::cerr.rdbuf(cerr_buffer);
  if (!read) return InvalidArgumentError(map_path + " is not an OctoMap binary tree");
  // Robots move 0.3-2 m/s; every 0.1 s places their bodies within a voxel or two of any instant.
  const sim::SurfaceDistance truth(**mission, 0.1);
  a.voxel = tree.getResolution();
  for (auto it = tree.begin_leafs(); it != tree.end_leafs(); ++it) {
    if (!tree.isNodeOccupied(*it)) continue;
    const octomap::point3d c = it.getCoordinate();
    ++a.occupied;
    a.near += truth.Distance(T_world_map * Eigen::Vector3d(c.x(), c.y(), c.z()), a.voxel) <= a.voxel;
  }
  return a;
}

}  // namespace cairn
