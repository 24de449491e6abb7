#include "detection/tag_pose_estimator.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <opencv2/calib3d.hpp>
#include <opencv2/core.hpp>

namespace cairn {
namespace {

Eigen::Isometry3d FromRvecTvec(const cv::Mat& rvec, const cv::Mat& tvec) {
  cv::Mat R;
  cv::Rodrigues(rvec, R);
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) T.linear()(r, c) = R.at<double>(r, c);
    T.translation()[r] = tvec.at<double>(r);
  }
  return T;
}

}  // namespace

Eigen::Matrix<double, 6, 1> TagPoseEstimator::Deviation(const Eigen::Isometry3d& T_ref, const Eigen::Isometry3d& T) {
  const Eigen::Isometry3d D = T_ref.inverse() * T;
  const Eigen::AngleAxisd aa(D.linear());
  Eigen::Matrix<double, 6, 1> d;
  d.head<3>() = D.translation();
  d.tail<3>() = aa.angle() * aa.axis();
  return d;
}

std::vector<std::pair<Eigen::Isometry3d, double>> TagPoseEstimator::Solve(
    const std::array<Eigen::Vector2d, 4>& corners, const PinholeRadTan& camera) const {
  const double h = 0.5 * options_.tag_size;
  const std::vector<cv::Point3d> object = {{-h, h, 0.0}, {h, h, 0.0}, {h, -h, 0.0}, {-h, -h, 0.0}};
  std::vector<cv::Point2d> image;
  for (const Eigen::Vector2d& c : corners) image.emplace_back(c.x(), c.y());
  const cv::Matx33d K(camera.fx, 0.0, camera.cx, 0.0, camera.fy, camera.cy, 0.0, 0.0, 1.0);
  const cv::Vec4d distortion(camera.k1, camera.k2, camera.p1, camera.p2);
  std::vector<cv::Mat> rvecs, tvecs;
  std::vector<std::pair<Eigen::Isometry3d, double>> out;
  try {
    cv::solvePnPGeneric(object, image, K, distortion, rvecs, tvecs, false, cv::SOLVEPNP_IPPE_SQUARE);
  } catch (const cv::Exception&) {
    return out;  // degenerate corners (e.g. all on a line): no solution
  }
  for (size_t i = 0; i < rvecs.size(); ++i) {
    // RMS over the 4 corners of the distance to the projection (computed here, so that its
    // definition does not depend on OpenCV's).
    std::vector<cv::Point2d> projected;
    cv::projectPoints(object, rvecs[i], tvecs[i], K, distortion, projected);
    double sse = 0.0;
    for (size_t c = 0; c < 4; ++c) {
      const cv::Point2d d = projected[c] - image[c];
      sse += d.dot(d);
    }
    out.emplace_back(FromRvecTvec(rvecs[i], tvecs[i]), std::sqrt(sse / 4.0));
  }
  std::sort(out.begin(), out.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  return out;
}

Eigen::Matrix<double, 6, 8> TagPoseEstimator::CornerJacobian(const std::array<Eigen::Vector2d, 4>& corners,
                                                             const PinholeRadTan& camera,
                                                             const Eigen::Isometry3d& T_cam_tag) const {
  constexpr double kStep = 0.02;  // px: well inside the linear range, well above the solver's noise
  Eigen::Matrix<double, 6, 8> J = Eigen::Matrix<double, 6, 8>::Zero();
  for (int j = 0; j < 8; ++j) {
    Eigen::Matrix<double, 6, 1> side[2];
    for (int k = 0; k < 2; ++k) {
      std::array<Eigen::Vector2d, 4> moved = corners;
      moved[j / 2][j % 2] += k == 0 ? -kStep : kStep;
      const auto s = Solve(moved, camera);
      if (s.empty()) return Eigen::Matrix<double, 6, 8>::Zero();
      side[k] = Deviation(T_cam_tag, s[0].first);
      for (size_t i = 1; i < s.size(); ++i) {
        const Eigen::Matrix<double, 6, 1> other = Deviation(T_cam_tag, s[i].first);
        if (other.tail<3>().norm() < side[k].tail<3>().norm()) side[k] = other;
      }
    }
    J.col(j) = (side[1] - side[0]) / (2.0 * kStep);
  }
  return J;
}

Expected<TagPose> TagPoseEstimator::Estimate(const std::array<Eigen::Vector2d, 4>& corners,
                                             const PinholeRadTan& camera) const {
  if (!(camera.fx > 0.0 && camera.fy > 0.0 && std::isfinite(camera.cx) && std::isfinite(camera.cy)))
    return InvalidArgumentError("tag pose: camera intrinsics need fx, fy > 0 and a finite centre");
  if (!(options_.tag_size > 0.0)) return InvalidArgumentError("tag pose: tag_size must be > 0");
  for (const Eigen::Vector2d& c : corners) {
    if (!c.allFinite()) return InvalidArgumentError("tag pose: a corner is not finite");
  }
  // The quad must be convex and not degenerate: IPPE needs a proper homography.
  double area = 0.0;
  for (size_t i = 0; i < 4; ++i) {
    const Eigen::Vector2d& a = corners[i];
    const Eigen::Vector2d& b = corners[(i + 1) % 4];
    area += a.x() * b.y() - b.x() * a.y();
  }
  if (!(std::abs(0.5 * area) >= 4.0))
    return InvalidArgumentError("tag pose: the corners enclose " + std::to_string(std::abs(0.5 * area)) +
                                " px^2, too small or degenerate");
  const auto solutions = Solve(corners, camera);
  if (solutions.empty()) return InternalError("tag pose: IPPE found no solution for these corners");
  TagPose pose;
  pose.T_cam_tag = solutions[0].first;
  pose.reprojection_error = solutions[0].second;
  if (solutions.size() > 1) {
    pose.has_alternative = true;
    pose.T_cam_tag_alternative = solutions[1].first;
    pose.alternative_reprojection_error = solutions[1].second;
  }
  const Eigen::Vector3d t = pose.T_cam_tag.translation();
  pose.distance = t.norm();
  // The tag's normal towards the camera is -z of the tag frame.
  const Eigen::Vector3d normal = -pose.T_cam_tag.linear().col(2);
  pose.view_angle = std::acos(std::clamp(normal.dot(-t) / std::max(pose.distance, 1e-12), -1.0, 1.0));
  if (!options_.sample_corners) return pose;

  // Eq. 6.9: every combination of +-corner_error on the 8 coordinates.
  std::array<Eigen::Matrix<double, 6, 1>, 257> deviations;
  deviations[0].setZero();
  size_t n = 1;
  for (unsigned mask = 0; mask < 256; ++mask) {
    std::array<Eigen::Vector2d, 4> moved = corners;
    for (unsigned bit = 0; bit < 8; ++bit) {
      const double step = (mask >> bit & 1u) ? options_.corner_error : -options_.corner_error;
      moved[bit / 2][static_cast<int>(bit % 2)] += step;
    }
    const auto s = Solve(moved, camera);
    if (s.empty()) continue;
    ++pose.solved_samples;
    deviations[n++] = Deviation(pose.T_cam_tag, s[0].first);
    if (pose.has_alternative) {
      const double to_best = Deviation(pose.T_cam_tag, s[0].first).tail<3>().norm();
      const double to_alternative = Deviation(pose.T_cam_tag_alternative, s[0].first).tail<3>().norm();
      pose.flipped_samples += to_alternative < to_best;
    }
  }
  Eigen::Matrix<double, 6, 1> mean = Eigen::Matrix<double, 6, 1>::Zero();
  for (size_t i = 0; i < n; ++i) mean += deviations[i];
  mean /= static_cast<double>(n);
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();
  for (size_t i = 0; i < n; ++i) sigma = sigma.cwiseMax((deviations[i] - mean).cwiseAbs());
  for (int k = 0; k < 6; ++k)
    sigma[k] = std::max(sigma[k], k < 3 ? options_.min_sigma_translation : options_.min_sigma_rotation);
  pose.covariance = sigma.cwiseAbs2().asDiagonal();
  for (size_t i = 0; i < n; ++i) pose.sample_covariance += (deviations[i] - mean) * (deviations[i] - mean).transpose();
  pose.sample_covariance /= static_cast<double>(n);
  pose.corner_jacobian = CornerJacobian(corners, camera, pose.T_cam_tag);
  return pose;
}

}  // namespace cairn
