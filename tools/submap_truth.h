#pragma once
// The true origins of a cairnd output folder's submaps (DIR/submaps/index.csv, written when the
// simulator gives truth), for the commands that score matches and landmarks against it.

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "common/status.h"
#include "mapping/matching/four_dof_transform.h"
#include "mapping/submap.h"

namespace cairn::tools {

struct SubmapTruth {
  std::string robot;
  uint64_t id = 0;                  // submap of the robot's current run
  FourDofTransform T_world_submap;  // true origin
};

// The rows that have a true pose; NotFound when the index cannot be opened, InvalidArgument (with
// the file and line) for a malformed pose.
Status ReadSubmapTruth(const std::string& dir, std::vector<SubmapTruth>* out);

struct SubmapWithTruth : SubmapTruth {
  std::shared_ptr<const Submap> submap;
};

// The rows with a true pose and their submap files (DIR/submaps/ROBOT-NNNNNN.submap); a row whose
// file is missing (a submap never finished) is left out, an unreadable file is an error.
Status ReadSubmapsWithTruth(const std::string& dir, std::vector<SubmapWithTruth>* out);

}  // namespace cairn::tools
