#pragma once
// Plain types shared by the stereo visual odometry, its pose estimator and the daemon stage.

#include <cstdint>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/timestamp.h"
#include "estimation/filter/filter_state.h"

namespace cairn {

// Why a frame produced no delta pose (kOk when it did).
enum class VoStatus : uint8_t {
  kOk,
  kBadExposure,       // blank, over-exposed or contrast-free image
  kSizeMismatch,      // image size differs from the calibration
  kTooFewFeatures,    // a keyframe candidate without enough triangulated corners
  kTooFewTracks,      // too few keyframe features found again in the current image
  kTooFewInliers,     // RANSAC found no consistent motion
  kDegenerate,        // inliers clustered or estimate too uncertain
  kDroppedFrame,      // the camera numbered a frame that never arrived
  kNoKeyframe,        // nothing to match against yet (the frame became the first keyframe)
};
inline constexpr int kVoStatusCount = 9;
const char* VoStatusName(VoStatus s);

// A rectified stereo pair's pinhole model (both cameras share f, cx, cy; right = left shifted by
// the baseline along x).
struct RectifiedStereoCamera {
  int width = 0;
  int height = 0;
  double f = 0.0;
  double cx = 0.0;
  double cy = 0.0;
  double baseline = 0.0;  // m
};

// A point seen in both images of a rectified pair: left and right columns and the mean row.
struct StereoObservation {
  double u_left = 0.0;
  double u_right = 0.0;
  double v = 0.0;
};

// Triangulated point in the left camera frame with its covariance.
struct StereoPoint {
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Matrix3d cov = Eigen::Matrix3d::Identity();
};

// Triangulates `o`: columns carry `pixel_sigma`, the row (mean of two) pixel_sigma / sqrt(2),
// which makes the covariance diagonal equal to thesis eq. 5.2 (stereo/stereo_error_model.h).
// False when the disparity is below `min_disparity`.
bool TriangulateStereo(const RectifiedStereoCamera& cam, const StereoObservation& o, double pixel_sigma,
                       double min_disparity, StereoPoint* out);

}  // namespace cairn
