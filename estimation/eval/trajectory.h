#pragma once
// A timestamped trajectory of body poses T_frame_body in one named frame, and its exchange formats:
// TUM (`t tx ty tz qx qy qz qw`, seconds), EuRoC/ASL CSV (`ns, p xyz, q wxyz[, ...]`, the
// ground-truth layout) and KITTI odometry (`r11 r12 r13 tx ... r33 tz`, one 3x4 row-major matrix
// per line; times in a separate file since KITTI poses carry none).

#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/status.h"
#include "common/timestamp.h"

namespace cairn {

struct StampedPose {
  Timestamp time;
  Eigen::Isometry3d T_frame_body = Eigen::Isometry3d::Identity();
};

enum class TrajectoryFormat { kTum, kEurocCsv, kKitti };

struct Trajectory {
  std::string frame;  // e.g. "local/3", "global", "world"
  std::vector<StampedPose> poses;
};

class TrajectoryIo {
 public:
  // From a file name: *.tum / *.txt -> TUM, *.csv -> EuRoC, *.kitti -> KITTI.
  static Expected<TrajectoryFormat> FormatFromPath(const std::string& path);
  static Expected<TrajectoryFormat> FormatFromName(const std::string& name);

  static std::string Format(const Trajectory& t, TrajectoryFormat format);
  // KITTI: the companion times file (seconds, one per line), as KITTI's times.txt.
  static std::string KittiTimes(const Trajectory& t);

  // Reads TUM or EuRoC CSV (EuRoC rows may carry extra columns, e.g. velocity and biases, which
  // are ignored). Errors name file and line. KITTI needs `times_path` for timestamps; without it
  // poses get their line index in seconds.
  static Expected<Trajectory> Read(const std::string& path, TrajectoryFormat format,
                                   const std::string& times_path = "");
};

}  // namespace cairn
