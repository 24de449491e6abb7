#pragma once
// Where the graph last placed this robot and every other tag carrier (teammates and landmarks), in
// its global frame: the detection stage turns it into the image regions where their tags should
// appear (thesis 6.2.1's fast path). Written by the graph thread, copied by the detection thread.

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/timestamp.h"

namespace cairn {

struct CarrierPredictions {
  struct Carrier {
    std::string name;  // as in the tag carrier table
    bool landmark = false;
    Timestamp time;    // of the estimate (landmarks: the graph's time, they do not move)
    Eigen::Isometry3d T_global_carrier = Eigen::Isometry3d::Identity();
  };
  bool valid = false;  // this robot is placed
  Timestamp time;      // of this robot's latest estimate in the graph
  Eigen::Isometry3d T_global_body = Eigen::Isometry3d::Identity();
  std::vector<Carrier> carriers;
};

}  // namespace cairn
