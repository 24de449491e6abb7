#pragma once
// g2o pose-graph files: VERTEX_SE3:QUAT / EDGE_SE3:QUAT and planar VERTEX_SE2 / EDGE_SE2 (lifted
// to 3-D: z, roll and pitch held by a stiff information). A directory is read as a multi-robot set,
// one file per robot, merged by 64-bit key; inter-robot edges listed in both files count once.
// Malformed lines are rejected with "file:line: what".
//
// Information conventions: the 3-D rotation block is taken as the information of the rotation
// vector (as SE-Sync and Ceres' examples read it); g2o's own solver reads it for the quaternion's
// vector part, which differs by a factor 4 on that block, not in the optimum's location.

#include <string>

#include "common/status.h"
#include "estimation/graph/pose_graph.h"

namespace cairn {

// Reads one file, or every *.g2o file in a directory (sorted by name) into one graph.
Expected<PoseGraph> ReadG2o(const std::string& path);
// Parses g2o text; `name` only labels errors.
Status ParseG2o(const std::string& text, const std::string& name, PoseGraph& graph);
// Writes SE2 records when every edge came from SE2, SE3:QUAT otherwise.
Status WriteG2o(const std::string& path, const PoseGraph& graph);
std::string FormatG2o(const PoseGraph& graph);

}  // namespace cairn
