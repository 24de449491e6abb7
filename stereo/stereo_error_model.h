#pragma once
// Propagated stereo reconstruction error (thesis 5.1.1, eqs. 5.2 and 5.4, after Hirschmueller).
// Points are in the rectified left camera frame (z into the image); f in pixels, b in metres, and
// the pixel error is the standard deviation of each image coordinate.

#include <Eigen/Core>

namespace cairn {

class StereoErrorModel {
 public:
  StereoErrorModel(double focal_px, double baseline, double pixel_error_px = 0.5)
      : f_(focal_px), b_(baseline), dp_(pixel_error_px) {}

  // Per-axis error of one reconstructed point (eq. 5.2).
  Eigen::Vector3d PointError(const Eigen::Vector3d& p) const;
  // Depth error only (eq. 5.2c); grows with the square of the depth.
  double DepthError(double depth) const;
  // Error of the distance between two reconstructed points (eqs. 5.3, 5.4). Zero when p == q.
  double DistanceError(const Eigen::Vector3d& p, const Eigen::Vector3d& q) const;
  // Largest depth whose depth error stays within `max_depth_error`.
  double MaxDepthForError(double max_depth_error) const;

  double focal_px() const { return f_; }
  double baseline() const { return b_; }
  double pixel_error_px() const { return dp_; }

 private:
  double f_;
  double b_;
  double dp_;
};

}  // namespace cairn
