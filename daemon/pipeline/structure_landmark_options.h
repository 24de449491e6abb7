#pragma once
// `matching.plane_landmarks:` and `matching.line_landmarks:` planar faces and straight edges of
// submaps as landmarks of the graph (paper 003's plane landmarks, paper 000's line landmarks),
// observed by every submap, of any robot, that sees them.

#include "common/options_visitor.h"
#include "mapping/matching/line_associator.h"
#include "mapping/matching/plane_associator.h"

namespace cairn {

template <class AssociationOptions>
struct StructureLandmarkOptions {
  bool enabled = true;
  // Pairs of submaps whose origins lie farther apart than this (xy) share no face or edge worth
  // trying.
  double max_origin_distance = 40.0;  // m
  bool write_csv = true;              // OUT/planes.csv, OUT/lines.csv
  AssociationOptions association;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("max_origin_distance", max_origin_distance, 0.0, 1e6, "m");
    v.Flag("write_csv", write_csv);
    v.Section("association", association);
  }
};

using PlaneLandmarkOptions = StructureLandmarkOptions<PlaneAssociationOptions>;
using LineLandmarkOptions = StructureLandmarkOptions<LineAssociationOptions>;

}  // namespace cairn
