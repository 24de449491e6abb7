#pragma once
// Draws the SLAM graph for Foxglove's 3D panel as one foxglove.SceneUpdate entity per robot in the
// map frame: submap origins as spheres stretched to their 2-sigma position ellipsoids (at least a
// few centimetres, so an exactly known origin stays visible), robot poses as small spheres,
// frame switches and pose factors as line lists in two colours, and an "sN" label per origin.

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
