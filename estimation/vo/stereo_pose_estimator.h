#pragma once
// Relative pose between two stereo frames from triangulated point pairs (Hirschmueller et al.
// 2002 style): RANSAC over 3-point absolute orientations, then a Ceres refinement that weights
// each pair's 3-D difference by the covariance of both points. The pose and its 6x6 covariance
// then come from a two-frame bundle adjustment of the inliers' pixels
// (two_frame_bundle_adjuster.h), which the alignment's own weights bias short; with
// vo.bundle_iterations 0, from the alignment.
//
// Convention: T_kf_cur maps current-camera points into the keyframe camera (p_kf = R p_cur + t).
// Covariance of [translation; rotation] with t = t_hat + dt and R = R_hat Exp(dtheta).

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Geometry>

#include "estimation/vo/two_frame_bundle_adjuster.h"
#include "estimation/vo/vo_options.h"
#include "estimation/vo/vo_types.h"

namespace cairn {

struct PoseEstimate {
  VoStatus status = VoStatus::kTooFewInliers;
  Eigen::Isometry3d T_kf_cur = Eigen::Isometry3d::Identity();
  Matrix6d covariance = Matrix6d::Identity();
  int inliers = 0;
  int ransac_iterations = 0;
  double rms_mahalanobis = 0.0;  // sqrt of the chi-square per pair over its 3 degrees of freedom
};

class StereoPoseEstimator {
 public:
  StereoPoseEstimator(const VoOptions& options, const RectifiedStereoCamera& camera);

  // kf[i] and cur[i] are the same scene point, triangulated from kf_seen[i] and cur_seen[i].
  // `seed` makes RANSAC reproducible. inlier_mask() holds the final inliers afterwards.
  PoseEstimate Estimate(std::span<const StereoObservation> kf_seen,
                        std::span<const StereoObservation> cur_seen, std::span<const StereoPoint> kf,
                        std::span<const StereoPoint> cur, uint64_t seed);

  const std::vector<uint8_t>& inlier_mask() const { return inliers_; }

 private:
  int Score(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, std::span<const StereoPoint> kf,
            std::span<const StereoPoint> cur, std::vector<uint8_t>* mask) const;
  // One weighted Gauss-Newton step on the pairs in `mask` (local optimization inside RANSAC).
  bool GaussNewtonStep(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur,
                       const std::vector<uint8_t>& mask, Eigen::Matrix3d* R, Eigen::Vector3d* t) const;
  bool Refine(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur, Eigen::Matrix3d* R,
              Eigen::Vector3d* t) const;
  // The alignment's information of [dt; dtheta] at (R, t) and its chi-square over the inliers.
  Matrix6d AlignmentInformation(std::span<const StereoPoint> kf, std::span<const StereoPoint> cur,
                                const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double* chi2) const;
  // The bundle adjustment of the inliers, once more without those it finds beyond the inlier
  // threshold. False when it fails.
  bool Adjust(std::span<const StereoObservation> kf_seen, std::span<const StereoObservation> cur_seen,
              std::span<const StereoPoint> kf, Eigen::Matrix3d* R, Eigen::Vector3d* t, Matrix6d* information,
              double* chi2, int* inliers);

  VoOptions options_;
  TwoFrameBundleAdjuster bundle_;
  std::vector<double> trace_bound_;  // trace of cov_kf + cov_cur per pair
  std::vector<uint8_t> inliers_, candidate_;
};

}  // namespace cairn
