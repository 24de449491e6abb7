#pragma once
// How well a simulated run's voxel map (map.bt in its output folder) lies on the simulated world's
// true surfaces: the terrain, the lander and its markers, and every robot wherever it was (sampled
// every 0.1 s). The measure: the share of occupied voxels whose centre is within one voxel
// of a true surface. `cairn summary` prints it; tests assert it.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/status.h"

namespace cairn {

struct SimulatedMapAccuracy {
  int64_t occupied = 0;  // occupied leaves at the finest level
  int64_t near = 0;      // ...within one voxel of a true surface
  double voxel = 0.0;    // m
  // Keys of the run's config.yaml that this version does not know or misses (an earlier version
  // wrote it); defaults were used for the missing ones.
  std::vector<std::string> config_notes;
  double fraction() const { return occupied > 0 ? static_cast<double>(near) / static_cast<double>(occupied) : 0.0; }
};

// `dir` is a cairnd output folder of a simulated run (map.bt, config.yaml); T_world_map places the
// map's frame (trajectory.tum's) in the world, e.g. the trajectory's alignment to the ground truth.
Expected<SimulatedMapAccuracy> ScoreSimulatedMap(const std::string& dir, const Eigen::Isometry3d& T_world_map);

}  // namespace cairn
