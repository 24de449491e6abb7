#pragma once
// How right a simulated team's plane landmarks are (`cairn summary`): every observation in the
// robots' planes.csv is taken to the simulator's world with its submap origin's true pose
// (submaps/index.csv), and compared with the face that started its landmark. An observation is
// wrong when the two faces are not the same true plane: normals more than 5 deg apart, or its
// centroid more than 0.25 m off the first face's plane. A wrong one "survives the graph" when
// its residual at the end is still inside the association gate (chi2(3) 11.34), so the robust
// loss has not set it aside.

#include <string>
#include <vector>

#include "common/status.h"

namespace cairn::tools {

struct PlaneLandmarkScore {
  int landmarks = 0;
  int observations = 0;  // distinct, over all robots' files
  int scored = 0;        // with both origins' truth
  int wrong = 0;
  int wrong_surviving = 0;
  double max_angle_deg = 0.0;  // of the right ones
  double max_distance = 0.0;   // m, of the right ones
};

// `dirs`: cairnd output folders of one simulated team mission (planes.csv, submaps/index.csv).
Expected<PlaneLandmarkScore> ScorePlaneLandmarks(const std::vector<std::string>& dirs);

}  // namespace cairn::tools
