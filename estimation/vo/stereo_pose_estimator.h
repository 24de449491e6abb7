#pragma once
// Relative pose between two stereo frames from triangulated point pairs (Hirschmueller et al.
// 2002 style): RANSAC over 3-point absolute orientations, then a Ceres refinement that weights
// each pair's 3-D difference by the covariance of both points, and the 6x6 covariance of the
// result from the refinement's Jacobians.
//
// Convention: T_kf_cur maps current-camera points into the keyframe camera (p_kf = R p_cur + t).
// Covariance of [translation; rotation] with t = t_hat + dt and R = R_hat Exp(dtheta).

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "estimation/vo/vo_options.h"
#include "estimation/vo/vo_types.h"

namespace cairn {

struct PoseEstimate {
  VoStatus status = VoStatus::kTooFewInliers;
  Eigen::Isometry3d T_kf_cur = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
  int inliers = 0;
  int ransac_iterations = 0;
  double rms_mahalanobis = 0.0;  // sqrt of the mean squared whitened residual per point
};

class StereoPoseEstimator {
 public:
  explicit StereoPoseEstimator(const VoOptions& options);

  // kf[i] and cur[i] are the same scene point. `seed` makes RANSAC reproducible. inlier_mask()
  // holds the final inliers afterwards.
  PoseEstimate Estimate(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur, uint64_t seed);

  const std::vector<uint8_t>& inlier_mask() const { return inliers_; }

 private:
  int Score(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, std::span<const StereoPoint> kf,
            std::span<const StereoPoint> cur, std::vector<uint8_t>* mask) const;
  // One weighted Gauss-Newton step on the pairs in `mask` (local optimization inside RANSAC).
  bool GaussNewtonStep(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur,
                       const std::vector<uint8_t>& mask, Eigen::Matrix3d* R, Eigen::Vector3d* t) const;
  bool Refine(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur, Eigen::Matrix3d* R,
              Eigen::Vector3d* t) const;

  VoOptions options_;
  std::vector<double> trace_bound_;  // trace of cov_kf + cov_cur per pair
  std::vector<uint8_t> inliers_, candidate_;
};

}  // namespace cairn
