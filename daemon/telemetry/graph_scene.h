#pragma once
// The SLAM graph as the live view draws it, handed from the graph stage to its encoder.

#include <cstdint>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "estimation/graph/slam_graph_types.h"

namespace cairn {

// What the live view draws of the graph: its variables at their current estimates and its factors.
struct GraphScene {
  struct Node {
    uint64_t key = 0;
    Eigen::Isometry3d T_global = Eigen::Isometry3d::Identity();
    // Submap origins: marginal position covariance (m^2, global frame); zero when not computed.
    Eigen::Matrix3d position_covariance = Eigen::Matrix3d::Zero();
    std::string label;  // origins: "a/s3" (robot, submap), a restarted robot's earlier run "b.run0/s2"
  };
  struct Edge {
    uint64_t from = 0, to = 0;
    FactorKind kind = FactorKind::kFrameSwitch;
  };
  // A robot's (or an earlier run's) global trajectory, thinned for the view.
  struct Track {
    char robot = 0;
    std::string name;  // "a", "b.run0"
    std::vector<Eigen::Vector3d> positions;
  };
  // Only what the graph ties to this robot's frame: a teammate not connected yet is not drawn.
  std::vector<Node> origins, poses;
  std::vector<Edge> edges;
  std::vector<Track> tracks;
};

}  // namespace cairn
