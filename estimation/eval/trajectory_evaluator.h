#pragma once
// Accuracy of an estimated trajectory against ground truth: association by time, alignment
// (Umeyama SE(3), 4-DoF yaw + translation for gravity-aligned estimators, or none), absolute
// trajectory error, relative pose error over path-length segments (in % of distance and deg/m)
// and the drift between the first and the last associated pose.

#include <string>
#include <vector>

#include "common/status.h"
#include "estimation/eval/trajectory.h"

namespace cairn {

enum class TrajectoryAlignment { kSe3, kFourDof, kNone };
Expected<TrajectoryAlignment> ParseTrajectoryAlignment(const std::string& name);

struct TrajectoryEvalOptions {
  TrajectoryAlignment alignment = TrajectoryAlignment::kSe3;
  double max_time_difference = 0.01;            // s between associated poses
  std::vector<double> segment_lengths = {1.0, 2.0, 5.0};  // m of ground-truth path
};

struct SegmentError {
  double length = 0.0;  // m
  int pairs = 0;
  double translation_percent = 0.0;   // mean |t error| / length * 100
  double rotation_deg_per_m = 0.0;    // mean rotation error / length
};

struct TrajectoryEvalResult {
  int associated = 0;
  double path_length = 0.0;  // m, ground truth over the associated poses
  double duration = 0.0;     // s
  Eigen::Isometry3d T_gt_est = Eigen::Isometry3d::Identity();  // the alignment applied
  double ate_rmse = 0.0, ate_mean = 0.0, ate_max = 0.0;  // m
  std::vector<SegmentError> segments;
  // Relative pose error between the first and the last associated pose (alignment free).
  double drift_translation = 0.0;  // m
  double drift_rotation_deg = 0.0;
  double drift_yaw_deg = 0.0;      // about the ground truth's z axis
};

// Fails (naming the reason) when fewer than 2 poses associate or the alignment is degenerate.
Expected<TrajectoryEvalResult> EvaluateTrajectory(const Trajectory& ground_truth, const Trajectory& estimate,
                                                  const TrajectoryEvalOptions& options);

}  // namespace cairn
