#pragma once
// How right a simulated team's plane and line landmarks are (`cairn summary`): every observation in
// the robots' planes.csv (lines.csv) is taken to the simulator's world with its submap origin's true
// pose (submaps/index.csv), and compared with the face (edge) that started its landmark. An
// observation is wrong when the two are not the same true plane (line): normals (directions) more
// than 5 deg apart, or its centroid (middle) more than 0.25 m off the first one's plane (line). A
// wrong one "survives the graph" when its residual at the end is still inside the association gate
// (chi2(3) 11.34, chi2(4) 13.28), so the robust loss has not set it aside.

#include <string>
#include <vector>

#include "common/status.h"

namespace cairn::tools {

struct StructureLandmarkScore {
  int landmarks = 0;
  int observations = 0;  // distinct, over all robots' files
  int scored = 0;        // with both origins' truth
  int wrong = 0;
  int wrong_surviving = 0;
  double max_angle_deg = 0.0;  // of the right ones
  double max_distance = 0.0;   // m, of the right ones
};

enum class StructureKind { kPlane, kLine };

// `dirs`: cairnd output folders of one simulated team mission (planes.csv or lines.csv,
// submaps/index.csv).
Expected<StructureLandmarkScore> ScoreStructureLandmarks(const std::vector<std::string>& dirs,
                                                         StructureKind kind);

}  // namespace cairn::tools
