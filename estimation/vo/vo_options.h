#pragma once
// Options of the keyframe stereo visual odometry (estimation/vo/keyframe_visual_odometry.h) and of
// the interim frame-switch policy (7 m / 0.1 m sigma) used until submap partitioning drives it (thesis 5.1.3).

#include <cstdint>

#include "common/options_visitor.h"

namespace cairn {

inline constexpr int kMaxVoKeyframes = 8;

struct VoOptions {
  bool enabled = true;

  // Features: FAST corners in the rectified left image, the strongest per grid cell so that they
  // spread over the image.
  int64_t max_features = 300;
  int64_t grid_cols = 8;
  int64_t grid_rows = 6;
  int64_t fast_threshold = 12;  // gray levels
  int64_t border = 12;          // px kept free at the image edges

  // Sparse stereo: row search of a patch over [0, max_disparity], then Lucas-Kanade refinement
  // in the right image (sub-pixel).
  int64_t max_disparity = 128;   // px
  double min_disparity = 1.0;    // px; farther points carry no usable depth
  int64_t stereo_patch = 9;      // px, odd
  double stereo_max_sad = 20.0;  // mean absolute difference per pixel, gray levels
  double stereo_uniqueness = 0.9;  // best SAD must be below this fraction of the runner-up
  double max_row_error = 1.0;    // px between left and right rows after refinement

  // Temporal tracking: pyramidal Lucas-Kanade from the keyframe into the current image,
  // predicted by the last motion, with a forward-backward check.
  int64_t klt_window = 21;  // px, odd
  int64_t klt_levels = 3;
  int64_t klt_iterations = 20;
  double klt_max_fb_error = 0.5;  // px, forward-backward disagreement

  // Uncertainty: image coordinate sigma of every match (thesis 5.1.1 uses 0.5 px for depth);
  // points whose depth error (eq. 5.2c) exceeds max_depth_error are not used.
  double pixel_sigma = 0.3;      // px
  double max_depth_error = 0.5;  // m

  // RANSAC with 3-point absolute orientation, then Ceres refinement on the inliers.
  int64_t ransac_iterations = 200;
  double ransac_confidence = 0.999;
  double inlier_chi2 = 11.34;  // 3-DoF chi-square at 99 %
  int64_t min_inliers = 15;
  int64_t refine_iterations = 10;
  // Then a two-frame bundle adjustment of the inliers (points as variables, reprojection error
  // in both frames), whose pose and covariance are the result; 0 keeps the alignment's.
  int64_t bundle_iterations = 10;

  // Failure checks. A frame whose mean gray value is outside [min_mean, max_mean] or whose
  // standard deviation is below min_contrast is blank or over-exposed.
  double min_mean = 8.0;
  double max_mean = 247.0;
  double min_contrast = 4.0;
  int64_t min_tracks = 20;
  // Degenerate geometry: the estimate's 1-sigma bounds.
  double max_sigma_translation = 0.2;  // m
  double max_sigma_rotation_deg = 2.0;  // deg
  // Inliers must span this fraction of the image diagonal (not all on one spot).
  double min_inlier_spread = 0.1;

  // Keyframes (thesis 4.1.1: n = 5). A new one is taken when the tracked share of the reference
  // keyframe's features or the motion since it passes these thresholds.
  int64_t keyframes = 5;
  double keyframe_min_tracked_ratio = 0.5;
  double keyframe_translation = 0.15;  // m
  double keyframe_rotation_deg = 5.0;  // deg
  // After this many consecutive failures the odometry restarts from the next usable frame.
  int64_t max_consecutive_failures = 5;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Integer("max_features", max_features, 10, 5000, "features");
    v.Integer("grid_cols", grid_cols, 1, 64, "cells");
    v.Integer("grid_rows", grid_rows, 1, 64, "cells");
    v.Integer("fast_threshold", fast_threshold, 1, 255, "gray levels");
    v.Integer("border", border, 4, 200, "px");
    v.Integer("max_disparity", max_disparity, 8, 512, "px");
    v.Number("min_disparity", min_disparity, 0.1, 100.0, "px");
    v.Integer("stereo_patch", stereo_patch, 3, 31, "px");
    v.Number("stereo_max_sad", stereo_max_sad, 1.0, 255.0, "gray levels");
    v.Number("stereo_uniqueness", stereo_uniqueness, 0.1, 1.0, "");
    v.Number("max_row_error", max_row_error, 0.05, 5.0, "px");
    v.Integer("klt_window", klt_window, 5, 63, "px");
    v.Integer("klt_levels", klt_levels, 0, 6, "levels");
    v.Integer("klt_iterations", klt_iterations, 1, 100, "iterations");
    v.Number("klt_max_fb_error", klt_max_fb_error, 0.01, 10.0, "px");
    v.Number("pixel_sigma", pixel_sigma, 0.01, 5.0, "px");
    v.Number("max_depth_error", max_depth_error, 0.001, 100.0, "m");
    v.Integer("ransac_iterations", ransac_iterations, 1, 10000, "iterations");
    v.Number("ransac_confidence", ransac_confidence, 0.5, 0.999999, "");
    v.Number("inlier_chi2", inlier_chi2, 0.1, 1000.0, "chi-square");
    v.Integer("min_inliers", min_inliers, 3, 5000, "matches");
    v.Integer("refine_iterations", refine_iterations, 1, 100, "iterations");
    v.Integer("bundle_iterations", bundle_iterations, 0, 100, "iterations");
    v.Number("min_mean", min_mean, 0.0, 255.0, "gray levels");
    v.Number("max_mean", max_mean, 0.0, 255.0, "gray levels");
    v.Number("min_contrast", min_contrast, 0.0, 128.0, "gray levels");
    v.Integer("min_tracks", min_tracks, 3, 5000, "tracks");
    v.Number("max_sigma_translation", max_sigma_translation, 1e-4, 100.0, "m");
    v.Number("max_sigma_rotation_deg", max_sigma_rotation_deg, 1e-3, 180.0, "deg");
    v.Number("min_inlier_spread", min_inlier_spread, 0.0, 1.0, "");
    v.Integer("keyframes", keyframes, 1, kMaxVoKeyframes, "keyframes");
    v.Number("keyframe_min_tracked_ratio", keyframe_min_tracked_ratio, 0.0, 1.0, "");
    v.Number("keyframe_translation", keyframe_translation, 0.0, 100.0, "m");
    v.Number("keyframe_rotation_deg", keyframe_rotation_deg, 0.0, 180.0, "deg");
    v.Integer("max_consecutive_failures", max_consecutive_failures, 1, 1000, "frames");
  }

  Status Validate() const {
    if (stereo_patch % 2 == 0) return InvalidArgumentError("vo.stereo_patch must be odd");
    if (klt_window % 2 == 0) return InvalidArgumentError("vo.klt_window must be odd");
    if (min_mean >= max_mean) return InvalidArgumentError("vo.min_mean must be below vo.max_mean");
    if (min_tracks < min_inliers) return InvalidArgumentError("vo.min_tracks must be >= vo.min_inliers");
    return Status::Ok();
  }
};

// Until submap partitioning exists (mapping), the daemon switches the filter's frame of
// reference on the thesis' submap criteria (5.1.3).
struct FrameSwitchOptions {
  bool enabled = true;
  double max_distance = 7.0;         // m travelled in the current frame
  double max_position_sigma = 0.1;   // m, largest position standard deviation

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("max_distance", max_distance, 0.01, 1e6, "m");
    v.Number("max_position_sigma", max_position_sigma, 1e-4, 1e3, "m");
  }
};

}  // namespace cairn
