#include "estimation/graph/slam_graph_types.h"

#include "estimation/graph/line_factors.h"
#include "estimation/graph/plane_factors.h"
#include "estimation/graph/pose_factors.h"

namespace cairn {

bool IsUnary(FactorKind kind) {
  return kind == FactorKind::kPrior || kind == FactorKind::kAbsolutePose ||
         kind == FactorKind::kAbsolutePosition;
}

bool IsPoseEdge(FactorKind kind) {
  return !IsUnary(kind) && kind != FactorKind::kGnssPosition && !IsStructureObservation(kind);
}

int TangentSizeOf(uint64_t key) {
  switch (KindOfKey(key)) {
    case VariableKind::kPlane:
      return 3;
    case VariableKind::kLine:
      return 4;
    default:
      return 6;
  }
}

bool IsStructureVariable(uint64_t key) {
  return KindOfKey(key) == VariableKind::kPlane || KindOfKey(key) == VariableKind::kLine;
}

bool IsStructureObservation(FactorKind kind) {
  return kind == FactorKind::kPlaneObservation || kind == FactorKind::kLineObservation;
}

bool IsPositionFactor(FactorKind kind) {
  return kind == FactorKind::kAbsolutePosition || kind == FactorKind::kGnssPosition;
}

bool IsRobustFactor(FactorKind kind) {
  return kind == FactorKind::kDetection || kind == FactorKind::kLandmark || kind == FactorKind::kMatch ||
         kind == FactorKind::kAbsolutePose || kind == FactorKind::kAbsolutePosition ||
         kind == FactorKind::kGnssPosition || IsStructureObservation(kind);
}

PoseGraphEdge EdgeOfFactor(const SlamFactor& f) {
  PoseGraphEdge e;
  e.from = f.a;
  e.to = f.b;
  e.T_from_to = f.z;
  e.information = f.information;
  PoseGraph::SetIsotropicWeights(e);
  return e;
}

ceres::CostFunction* MakeFactorCostFunction(const SlamFactor& f) {
  switch (f.kind) {
    case FactorKind::kPrior:
    case FactorKind::kAbsolutePose: return AbsolutePoseResidual::Create(f.z, f.information);
    case FactorKind::kAbsolutePosition: return AbsolutePositionResidual::Create(f.position, f.position_information);
    case FactorKind::kGnssPosition:
      return GnssPositionResidual::Create(f.position, f.position_information, f.antenna);
    case FactorKind::kPlaneObservation:
      return PlaneObservationResidual::Create(f.plane, f.plane_information);
    case FactorKind::kLineObservation:
      return LineObservationResidual::Create(f.line_point, f.line_direction, f.line_information);
    default: return RelativePoseResidual::Create(f.z, f.information);
  }
}

}  // namespace cairn
