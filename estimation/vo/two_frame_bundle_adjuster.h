#pragma once
// Bundle adjustment of two rectified stereo frames: the relative pose and every point as
// variables, the stereo reprojection error (left column, right column, row) in both frames.
//
// Why not the 3-D alignment of the triangulated points alone: its weights come from each point's
// own measured depth, so a point measured too near weighs more than one measured too far, and the
// estimate comes out short (visibly so at small disparities). Here the pixels carry the noise
// and the points are fitted, which removes that correlation.
//
// Levenberg-Marquardt on the normal equations with the points eliminated by the Schur complement
// (one 3x3 block per point). The reduced 6x6 system at the optimum is the information of the pose
// with the points marginalized: its inverse is the pose covariance. Scratch buffers are kept
// between calls, so steady use allocates nothing.
//
// Convention as in stereo_pose_estimator.h: p_kf = R p_cur + t, covariance of [dt; dtheta] with
// t = t_hat + dt and R = R_hat Exp(dtheta). Points live in the keyframe camera.

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "estimation/vo/vo_types.h"

namespace cairn {

struct BundleResult {
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  Matrix6d information = Matrix6d::Zero();  // of [dt; dtheta], points marginalized
  double chi2 = 0.0;                        // whitened squared reprojection error, all points
  int points = 0;
  int iterations = 0;
};

class TwoFrameBundleAdjuster {
 public:
  // `pixel_sigma`: the columns' sigma; the row is the mean of two rows, so sigma / sqrt(2).
  TwoFrameBundleAdjuster(const RectifiedStereoCamera& camera, double pixel_sigma);

  // Adjusts the pairs whose `mask` entry is set, starting from (R, t) and from the points
  // triangulated in the keyframe. False when fewer than 3 points are usable or the system is
  // singular; the result is then untouched.
  bool Adjust(std::span<const StereoObservation> kf_seen, std::span<const StereoObservation> cur_seen,
              std::span<const StereoPoint> kf_points, std::span<const uint8_t> mask, const Eigen::Matrix3d& R,
              const Eigen::Vector3d& t, int max_iterations, BundleResult* result);

  // Whitened squared reprojection error of each adjusted pair in both frames (about chi-square
  // with 3 degrees of freedom: 6 residuals, 3 fitted coordinates); 0 for pairs outside the mask,
  // infinity for pairs in it that are not finite.
  const std::vector<double>& point_chi2() const { return point_chi2_; }

 private:
  struct PointBlock {
    Eigen::Matrix3d H_inv;               // damped point block, inverted
    Eigen::Matrix<double, 6, 3> H_pose;  // pose-point coupling
    Eigen::Vector3d g;                   // point gradient
  };

  // Total cost of the pose and points; false when a point falls behind either camera.
  bool Cost(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, const std::vector<Eigen::Vector3d>& X,
            double* cost);
  // Builds the damped reduced system; false when a point block is singular.
  bool Reduce(const Eigen::Matrix3d& R, const Eigen::Vector3d& t, double lambda, Matrix6d* S, Vector6d* g_s);

  RectifiedStereoCamera camera_;
  double sigma_col_, sigma_row_;
  // Scratch, kept between calls.
  std::vector<int> index_;
  std::vector<StereoObservation> seen_kf_, seen_cur_;
  std::vector<Eigen::Vector3d> X_, X_trial_;
  std::vector<PointBlock> blocks_;
  std::vector<double> point_chi2_;
};

}  // namespace cairn
