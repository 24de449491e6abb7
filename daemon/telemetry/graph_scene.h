#pragma once
// The SLAM graph as the live view draws it, handed from the graph stage to its encoder.

#include <cstdint>
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
  };
  struct Edge {
    uint64_t from = 0, to = 0;
    FactorKind kind = FactorKind::kFrameSwitch;
  };
  std::vector<Node> origins, poses;
  std::vector<Edge> edges;
};

}  // namespace cairn
