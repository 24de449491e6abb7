#pragma once
// Feeds a g2o pose graph into the online SlamGraph as a robot would see it (`cairn graph replay`):
// vertices in id order, each edge at the step where its later end appears (odometry as frame
// switches w, everything else as submap matches c), one Update() per step, and the own robot's
// first vertex under the prior. Plain ids belong to robot 'a'.

#include <vector>

#include "estimation/graph/pose_graph.h"
#include "estimation/graph/slam_graph.h"

namespace cairn {

struct GraphReplayResult {
  std::vector<double> step_seconds;  // one per step that added factors
  int reinitializations = 0;
  int full_solves = 0;         // merged into the online estimate
  int stale_full_solves = 0;   // dropped: the graph's structure changed while they ran
  // After the last step: waiting for the running full solve and merging it, as the robot's graph
  // would a moment later.
  double settle_seconds = 0.0;
  size_t unconnected = 0;
};

uint64_t SubmapKeyOfG2oId(uint64_t id);

// Writes the online estimate back into `graph`'s vertices. With a runner, full solves run in the
// background (the step times are the online thread's); without, inline.
Expected<GraphReplayResult> ReplayPoseGraph(PoseGraph& graph, SlamGraphOptions options,
                                            SlamGraph::BackgroundRunner runner = {});

}  // namespace cairn
