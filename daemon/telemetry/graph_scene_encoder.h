#pragma once
// Draws the SLAM graph for Foxglove's 3D panel as a foxglove.SceneUpdate in the map frame: one
// entity "graph/<robot>" with the submap origins of every robot in the graph as spheres stretched
// to their 2-sigma position ellipsoids (at least a few centimetres, so an exactly known origin
// stays visible) in their robot's colour with an "a/s3" label, robot poses as small spheres, frame
// switches and pose factors as line lists in two colours; and one entity "trajectory/<robot>" per
// robot the graph has placed, its global trajectory as a line strip in its colour.

#include <string>

#include "common/timestamp.h"
#include "daemon/telemetry/graph_scene.h"

namespace cairn {

class GraphSceneEncoder {
 public:
  // Valid until the next call.
  const std::string& Encode(Timestamp time, char robot, const GraphScene& scene);

 private:
  std::string out_;
};

}  // namespace cairn
