#pragma once
// Plane and line landmark observations (this robot's or a teammate's) as the graph's factors o,
// and the landmarks' graph keys. A landmark is named by its first observation: face or edge
// `index` of the submap at graph frame index `frame` of robot `letter`, so every robot of the
// team names it alike.

#include <cstdint>

#include "common/status.h"
#include "daemon/pipeline/team_input.h"
#include "estimation/graph/slam_graph.h"

namespace cairn {

// Faces are numbered below 256 in a submap, edges below 1024.
inline constexpr uint32_t kMaxPlaneIndex = 255;
inline constexpr uint32_t kMaxLineIndex = 1023;

uint64_t PlaneLandmarkKey(char letter, uint64_t frame, uint32_t plane);
uint64_t LineLandmarkKey(char letter, uint64_t frame, uint32_t line);

// The factor from the observing origin to the landmark, with where a new landmark starts (its
// first face's centroid moved onto the plane; its first edge's middle). InvalidArgument for a
// robot not in the team or an index out of range; the graph checks the measurement itself.
Expected<SlamFactor> PlaneObservationFactor(const TeamPlaneObservation& o);
Expected<SlamFactor> LineObservationFactor(const TeamLineObservation& o);

}  // namespace cairn
