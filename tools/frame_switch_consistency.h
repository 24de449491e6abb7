#pragma once
// How well the graph's frame-switch factors (w: a submap origin to the robot's next, with the
// filter's covariance of that motion) agree with the truth. The graph's relative estimates
// between submaps, and so the matcher's gate and eq. 6.3's "known better than the matcher
// measures", inherit this covariance along each robot's chain of origins: where it is narrower
// than the error, right matches fall outside the gate.

#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "estimation/graph/pose_graph.h"
#include "mapping/matching/four_dof_transform.h"

namespace cairn::tools {

struct FrameSwitchError {
  char robot = 'a';
  uint64_t from = 0;       // the earlier origin's index in its run
  double distance = 0.0;   // m, true xy distance between the two origins
  double error_xy = 0.0;   // m, of the next origin's position
  double error_yaw = 0.0;  // rad, absolute
  double scale = 1.0;      // the factor's distance between the origins over the true one
  double sigma_x = 0.0;    // m, the factor's
  double sigma_yaw = 0.0;  // rad, about z
  // e^T Sigma^-1 e over x, y, z and the rotation about z (origins are gravity aligned, so that is
  // yaw), with e the factor's residual at the true origins (translation in the next origin's
  // frame) and Sigma the factor's covariance marginalized to those four: 4 on average where
  // consistent.
  double nees = 0.0;
};

// The true origin of a robot's submap (by the robot's letter and the index in its run); nullopt
// where there is none.
using TrueOrigin = std::function<std::optional<FourDofTransform>(char robot, uint64_t index)>;

// Every factor between consecutive submap origins of one robot whose two ends have a true origin,
// in the graph's order. Factors whose information cannot be inverted are left out.
std::vector<FrameSwitchError> FrameSwitchErrors(const PoseGraph& graph, const TrueOrigin& truth);

}  // namespace cairn::tools
