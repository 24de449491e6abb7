#pragma once
// OUT/detections.csv: every tag sighting the graph was given (this robot's and its teammates'),
// with what became of it.

#include <string>
#include <vector>

#include "daemon/pipeline/graph_stage.h"

namespace cairn {

// Columns: time [ns], observer, observed, landmark, tag id, T_observer_observed (x y z [m],
// qw qx qy qz), its standard deviations (x y z [m], rx ry rz [rad]), distance [m], view angle
// [deg], status.
std::string FormatDetectionsCsv(const std::vector<DetectionRecord>& records);

}  // namespace cairn
