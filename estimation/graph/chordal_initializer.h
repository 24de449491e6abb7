#pragma once
// Chordal (rotation-first) initialization of a pose graph: rotations from the linear least-squares
// relaxation of sum kappa ||R_j - R_i R_ij||_F^2 (each matrix unconstrained, then projected onto
// SO(3)), then translations from the linear problem sum tau ||t_j - t_i - R_i t_ij||^2 with those
// rotations. The first vertex of each connected component keeps its pose (the gauge). Far better
// than odometry composition on graphs with long loops (Carlone et al., ICRA 2015).

#include "common/status.h"
#include "estimation/graph/pose_graph.h"

namespace cairn {

Status InitializeChordal(PoseGraph& graph);

}  // namespace cairn
