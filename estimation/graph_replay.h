#pragma once
// Feeds a g2o pose graph into the online SlamGraph as a robot would see it (`cairn graph replay`):
// vertices in id order, each edge at the step where its later end appears (odometry as frame
// switches w, everything else as submap matches c), one Update() per step, and the own robot's
// first vertex under the prior. Plain ids belong to robot 'a'.

#include <vector>

#include "estimation/pose_graph.h"
#include "estimation/slam_graph.h"

namespace cairn {

struct GraphReplayResult {
  std::vector<double> step_seconds;  // one per step that added factors
  int reinitializations = 0;
  size_t unconnected = 0;
};

uint64_t SubmapKeyOfG2oId(uint64_t id);

// Writes the online estimate back into `graph`'s vertices.
Expected<GraphReplayResult> ReplayPoseGraph(PoseGraph& graph, SlamGraphOptions options);

}  // namespace cairn
