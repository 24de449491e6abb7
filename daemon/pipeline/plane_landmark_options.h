#pragma once
// `matching.plane_landmarks:` planar faces of submaps as plane landmarks of the graph (paper 003's
// plane landmarks, observed by every submap, of any robot, that sees them).

#include "common/options_visitor.h"
#include "mapping/matching/plane_associator.h"

namespace cairn {

struct PlaneLandmarkOptions {
  bool enabled = true;
  // Pairs of submaps whose origins lie farther apart than this (xy) share no face worth trying.
  double max_origin_distance = 40.0;  // m
  bool write_csv = true;              // OUT/planes.csv
  PlaneAssociationOptions association;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("max_origin_distance", max_origin_distance, 0.0, 1e6, "m");
    v.Flag("write_csv", write_csv);
    v.Section("association", association);
  }
};

}  // namespace cairn
