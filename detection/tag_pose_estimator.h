#pragma once
// The 6-D pose of a detected square tag in the camera frame, with the uncertainty of thesis 6.2.3's
// online step.
//
// Frame: AprilTag's (as libapriltag's apriltag_pose.h): origin at the tag centre, x to the right
// and y down as the tag is printed, z into the tag (away from a camera that sees it); the corners
// in detection order are (-s/2, +s/2), (+s/2, +s/2), (+s/2, -s/2), (-s/2, -s/2) at z = 0.
//
// Pose: planar PnP by IPPE (OpenCV's SOLVEPNP_IPPE_SQUARE), which returns both local minima of the
// square's reprojection error; both are kept, best first, because far away or seen face-on the
// two explain the corners almost equally well (the flip of the tilt the thesis observed).
//
// Uncertainty (eq. 6.9): each of the 8 corner coordinates moved by +-corner_error gives 2^8 = 256
// corner sets; each is solved again and the largest deviation of each pose coordinate from the
// mean of all 257 solutions is taken as its standard deviation (a conservative, diagonal
// approximation, as in the thesis). Where the perturbations flip between the two minima the
// deviations, and so the sigmas, become large: that is how the flip shows. Coordinates are the
// right-hand tangent at T_cam_tag: T = T_cam_tag * (Exp(rho), Exp(phi)), rho in metres in the tag
// frame, phi the rotation vector in radians.

#include <array>
#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "common/status.h"
#include "hal/calibration.h"

namespace cairn {

using Matrix6d = Eigen::Matrix<double, 6, 6>;

struct TagPoseOptions {
  double tag_size = 0.16;           // m, outer edge of the black border
  double corner_error = 0.5;        // px, the delta p of eq. 6.9
  bool sample_corners = true;       // eq. 6.9's 256 solutions; off: no covariance
  double min_sigma_translation = 1e-4;  // m, floor of each translation sigma
  double min_sigma_rotation = 1e-4;     // rad, floor of each rotation sigma

  void Visit(OptionsVisitor& v) {
    v.Number("tag_size", tag_size, 1e-3, 10.0, "m");
    v.Number("corner_error", corner_error, 0.0, 10.0, "px");
    v.Flag("sample_corners", sample_corners);
    v.Number("min_sigma_translation", min_sigma_translation, 0.0, 1.0, "m");
    v.Number("min_sigma_rotation", min_sigma_rotation, 0.0, 1.0, "rad");
  }
};

struct TagPose {
  Eigen::Isometry3d T_cam_tag = Eigen::Isometry3d::Identity();
  double reprojection_error = 0.0;  // px, RMS over the 4 corners
  // IPPE's other minimum (when it found two) and its error.
  bool has_alternative = false;
  Eigen::Isometry3d T_cam_tag_alternative = Eigen::Isometry3d::Identity();
  double alternative_reprojection_error = 0.0;
  // Diagonal; the tangent described above. Zero when sampling is off.
  Matrix6d covariance = Matrix6d::Zero();
  // The full sample covariance of the same 257 solutions. In the linear regime the +-delta
  // combinations are a full factorial design, so this is exactly J diag(delta^2) J^T: the
  // first-order propagation of independent corner errors of sigma delta.
  Matrix6d sample_covariance = Matrix6d::Zero();
  // d(pose tangent) / d(corner px), columns in the order x0, y0, x1, ... of `corners`: central
  // differences of 0.02 px that stay on the best minimum (the nearer of each solve's two
  // solutions). Where that minimum is the right one, pose error = J * corner error almost exactly
  // (on rendered tags to about 1 % of the error): the +-corner_error perturbations above are far
  // outside that linear range once the tag is tilted little or far away. Zero without sampling.
  Eigen::Matrix<double, 6, 8> corner_jacobian = Eigen::Matrix<double, 6, 8>::Zero();
  int solved_samples = 0;   // perturbed corner sets IPPE solved (of 256)
  int flipped_samples = 0;  // perturbed solutions nearer the alternative than the best
  double distance = 0.0;    // m, camera to tag centre
  double view_angle = 0.0;  // rad, between the tag's normal and the direction to the camera
};

class TagPoseEstimator {
 public:
  explicit TagPoseEstimator(const TagPoseOptions& options = {}) : options_(options) {}

  // `corners` in detection order (see above), px of an image with `camera`'s calibration.
  Expected<TagPose> Estimate(const std::array<Eigen::Vector2d, 4>& corners, const PinholeRadTan& camera) const;

  // The tangent deviation of `T` from `T_ref` (see the header comment).
  static Eigen::Matrix<double, 6, 1> Deviation(const Eigen::Isometry3d& T_ref, const Eigen::Isometry3d& T);

 private:
  // Both IPPE solutions, best first; empty when the solver fails.
  std::vector<std::pair<Eigen::Isometry3d, double>> Solve(const std::array<Eigen::Vector2d, 4>& corners,
                                                          const PinholeRadTan& camera) const;
  // TagPose::corner_jacobian at the minimum T_cam_tag; zero where a step leaves IPPE without a solution.
  Eigen::Matrix<double, 6, 8> CornerJacobian(const std::array<Eigen::Vector2d, 4>& corners, const PinholeRadTan& camera,
                                             const Eigen::Isometry3d& T_cam_tag) const;

  TagPoseOptions options_;
};

}  // namespace cairn
