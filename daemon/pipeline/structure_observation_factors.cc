#include "daemon/pipeline/structure_observation_factors.h"

#include <string>

#include "estimation/graph/line_factors.h"
#include "estimation/graph/plane_factors.h"

namespace cairn {
namespace {

// The run in the top bits as in frame indices; the frame and the landmark's index (`bits` wide)
// below them.
uint64_t StructureLandmarkKey(VariableKind kind, char letter, uint64_t frame, uint32_t index, int bits) {
  const uint64_t mask = (uint64_t{1} << bits) - 1;
  const uint64_t local = ((LocalIndex(frame) << bits) | (index & mask)) & ((uint64_t{1} << kRunShift) - 1);
  return VariableKey(kind, letter, (static_cast<uint64_t>(RunOfIndex(frame)) << kRunShift) | local);
}

// Both robots in the team, both indices (the landmark's and the observer's) in range.
Status CheckNaming(const TeamLandmarkNames& o, uint32_t index, uint32_t observer_index, uint32_t max,
                   const std::string& what) {
  if (o.observer_letter == 0 || o.creator_letter == 0) {
    return InvalidArgumentError(what + " observation naming a robot not in the team");
  }
  if (index > max || observer_index > max) {
    return InvalidArgumentError(what + " observation: " + what + " index above " + std::to_string(max));
  }
  return Status::Ok();
}

}  // namespace

uint64_t PlaneLandmarkKey(char letter, uint64_t frame, uint32_t plane) {
  return StructureLandmarkKey(VariableKind::kPlane, letter, frame, plane, 8);
}

uint64_t LineLandmarkKey(char letter, uint64_t frame, uint32_t line) {
  return StructureLandmarkKey(VariableKind::kLine, letter, frame, line, 10);
}

Expected<SlamFactor> PlaneObservationFactor(const TeamPlaneObservation& o) {
  if (Status s = CheckNaming(o, o.plane, o.observer_plane, kMaxPlaneIndex, "plane"); !s.ok()) return s;
  SlamFactor f;
  f.kind = FactorKind::kPlaneObservation;
  f.a = VariableKey(VariableKind::kSubmap, o.observer_letter, o.frame);
  f.b = PlaneLandmarkKey(o.creator_letter, o.creator_frame, o.plane);
  const Eigen::Vector3d n = o.normal.normalized();
  f.plane = Eigen::Vector4d(n.x(), n.y(), n.z(), o.offset);
  f.plane_information = o.covariance.inverse();
  f.plane_information = 0.5 * (f.plane_information + f.plane_information.transpose());
  f.z = PlaneLandmarkFrame(n, o.centroid - (n.dot(o.centroid) + o.offset) * n);
  return f;
}

Expected<SlamFactor> LineObservationFactor(const TeamLineObservation& o) {
  if (Status s = CheckNaming(o, o.line, o.observer_line, kMaxLineIndex, "line"); !s.ok()) return s;
  SlamFactor f;
  f.kind = FactorKind::kLineObservation;
  f.a = VariableKey(VariableKind::kSubmap, o.observer_letter, o.frame);
  f.b = LineLandmarkKey(o.creator_letter, o.creator_frame, o.line);
  f.line_point = o.point;
  f.line_direction = o.direction.normalized();
  f.line_information = o.covariance.inverse();
  f.line_information = 0.5 * (f.line_information + f.line_information.transpose());
  f.z = LineLandmarkFrame(f.line_direction, o.point);
  return f;
}

}  // namespace cairn
