#pragma once
// submaps/index.csv: each submap of the run with the time its origin began and, for simulated
// runs, the origin's true pose in the simulator's world (x, y, z, yaw of the body at that time:
// a frame switch puts the new origin at the body, roll and pitch left out). Matches are scored
// against T_a_b = T_world_a^-1 T_world_b from these rows.

#include <cstdint>
#include <map>
#include <string>

#include "common/timestamp.h"
#include "estimation/eval/trajectory.h"

namespace cairn {

// `truth` may be null (no ground truth): the true_* columns stay empty.
std::string FormatSubmapIndex(const std::string& robot, const std::map<uint64_t, Timestamp>& origin_times,
                              const Trajectory* truth);

}  // namespace cairn
