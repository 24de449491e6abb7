#include "detection/tag_pose_estimator.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>
#include <random>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "detection/tag_detector.h"
#include "detection/testing/rendered_tag.h"

namespace cairn {
namespace {

const PinholeRadTan kCamera{1024, 508, 1080.0, 1080.0, 512.0, 254.0};  // the rover's, rectified

// A tag `distance` ahead, turned by `tilt` about the camera's x axis (0: facing the camera).
Eigen::Isometry3d TagAt(double distance, double tilt, const Eigen::Vector2d& offset = {0.1, -0.05}) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.translation() = Eigen::Vector3d(offset.x(), offset.y(), distance);
  T.linear() = Eigen::AngleAxisd(tilt, Eigen::Vector3d::UnitX()).toRotationMatrix() *
               Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return T;
}

std::array<Eigen::Vector2d, 4> Project(const Eigen::Isometry3d& T_cam_tag, double size) {
  const double h = 0.5 * size;
  const Eigen::Vector3d object[4] = {{-h, h, 0.0}, {h, h, 0.0}, {h, -h, 0.0}, {-h, -h, 0.0}};
  std::array<Eigen::Vector2d, 4> out;
  for (size_t k = 0; k < 4; ++k) out[k] = kCamera.Project(T_cam_tag * object[k]);
  return out;
}

TEST(TagPoseEstimatorTest, ExactCornersGiveTheExactPose) {
  const Eigen::Isometry3d truth = TagAt(2.0, 35 * kDegree);
  const auto pose = TagPoseEstimator().Estimate(Project(truth, 0.16), kCamera);
  ASSERT_TRUE(pose.ok()) << pose.status().ToString();
  EXPECT_LT(TagPoseEstimator::Deviation(truth, pose->T_cam_tag).norm(), 1e-6);
  EXPECT_LT(pose->reprojection_error, 1e-6);
  EXPECT_NEAR(pose->distance, truth.translation().norm(), 1e-6);
  EXPECT_NEAR(pose->view_angle, std::acos(-(truth.linear().col(2)).dot(-truth.translation().normalized())), 1e-6);
  EXPECT_TRUE(pose->has_alternative);
}

TEST(TagPoseEstimatorTest, TheCornerJacobianPredictsThePoseChangeOfSmallCornerErrors) {
  const TagPoseEstimator estimator;
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0.0, 0.2);
  // Farther, 0.2 px already moves a 0.16 m tag's tilt beyond the linear range (at 6 m, 10 deg
  // tilt, the prediction is off by twice the change): there the table's level and the mixture
  // with the other minimum carry the covariance.
  for (const double d : {1.0, 3.0}) {
    for (const double tilt : {10 * kDegree, 45 * kDegree}) {
      const auto corners = Project(TagAt(d, tilt), 0.16);
      const auto pose = estimator.Estimate(corners, kCamera);
      ASSERT_TRUE(pose.ok());
      ASSERT_GT(pose->corner_jacobian.norm(), 0.0);
      auto moved = corners;
      Eigen::Matrix<double, 8, 1> e;
      for (int j = 0; j < 8; ++j) moved[j / 2][j % 2] += e[j] = noise(rng);
      TagPoseOptions plain;
      plain.sample_corners = false;
      const auto after = TagPoseEstimator(plain).Estimate(moved, kCamera);
      ASSERT_TRUE(after.ok());
      Eigen::Matrix<double, 6, 1> actual = TagPoseEstimator::Deviation(pose->T_cam_tag, after->T_cam_tag);
      if (after->has_alternative) {  // the same minimum, whichever IPPE ranks first after the move
        const auto other = TagPoseEstimator::Deviation(pose->T_cam_tag, after->T_cam_tag_alternative);
        if (other.tail<3>().norm() < actual.tail<3>().norm()) actual = other;
      }
      const Eigen::Matrix<double, 6, 1> predicted = pose->corner_jacobian * e;
      EXPECT_LT((actual - predicted).norm(), 0.1 * actual.norm()) << d << " m, tilt " << tilt;
    }
  }
}

TEST(TagPoseEstimatorTest, SigmasGrowWithDistanceAndDepthIsTheWeakAxis) {
  const TagPoseEstimator estimator;
  double previous_depth_sigma = 0.0;
  for (const double d : {1.0, 2.0, 4.0, 8.0}) {
    const auto pose = estimator.Estimate(Project(TagAt(d, 20 * kDegree), 0.16), kCamera);
    ASSERT_TRUE(pose.ok());
    const Eigen::Matrix<double, 6, 1> sigma = pose->covariance.diagonal().cwiseSqrt();
    std::printf("[ tagpose ] %.0f m: sigma x y z %.4f %.4f %.4f m, rotation %.2f %.2f %.2f deg, %d flipped\n", d,
                sigma[0], sigma[1], sigma[2], sigma[3] / kDegree, sigma[4] / kDegree, sigma[5] / kDegree,
                pose->flipped_samples);
    // Depth (along the line of sight, about the tag's z here) is the least certain translation.
    EXPECT_GT(sigma[2], sigma[0]);
    EXPECT_GT(sigma[2], previous_depth_sigma);
    previous_depth_sigma = sigma[2];
  }
}

TEST(TagPoseEstimatorTest, RenderedTagsAreFoundWhereTheyAreWithinTheirSigmas) {
  TagDetectorOptions detector_options;
  detector_options.decimate = 1.0;
  TagDetector detector(detector_options);
  const TagPoseEstimator estimator;
  int cases = 0;
  double nees = 0.0;
  for (const double d : {1.0, 2.5, 4.0}) {
    for (const double tilt : {-50 * kDegree, -20 * kDegree, 10 * kDegree, 40 * kDegree}) {
      const Eigen::Isometry3d truth = TagAt(d, tilt, {0.2, 0.1});
      const cv::Mat image = testing::RenderTag(5, 0.16, truth, kCamera);
      const auto found = detector.Detect(testing::ImageOf(image));
      ASSERT_TRUE(found.ok());
      ASSERT_EQ(found->size(), 1u) << d << " m, " << tilt / kDegree << " deg";
      EXPECT_EQ((*found)[0].id, 5);
      // The detector's corners lie on the projected ones, in the estimator's order.
      const auto projected = Project(truth, 0.16);
      for (size_t k = 0; k < 4; ++k) EXPECT_LT(((*found)[0].corners[k] - projected[k]).norm(), 0.3) << k;
      const auto pose = estimator.Estimate((*found)[0].corners, kCamera);
      ASSERT_TRUE(pose.ok());
      const Eigen::Matrix<double, 6, 1> e = TagPoseEstimator::Deviation(pose->T_cam_tag, truth);
      const Eigen::Matrix<double, 6, 1> sigma = pose->covariance.diagonal().cwiseSqrt();
      std::printf("[ tagpose ] rendered %.1f m %+.0f deg: error %.4f m %.2f deg; 3 sigma %.4f m %.2f deg\n", d,
                  tilt / kDegree, e.head<3>().norm(), e.tail<3>().norm() / kDegree, 3 * sigma.head<3>().norm(),
                  3 * sigma.tail<3>().norm() / kDegree);
      for (int k = 0; k < 6; ++k) EXPECT_LT(std::abs(e[k]), 3.0 * sigma[k]) << d << " m, axis " << k;
      nees += e.dot(pose->covariance.inverse() * e);
      ++cases;
    }
  }
  EXPECT_EQ(cases, 12);
  // Eq. 6.9 takes the largest deviation as the sigma: conservative by design, so the mean NEES
  // lies far below the 6 of a calibrated 6-D Gaussian. Above 6 it would be overconfident.
  std::printf("[ tagpose ] mean NEES over %d rendered tags: %.4f (6 if calibrated)\n", cases, nees / cases);
  EXPECT_LT(nees / cases, 6.0);
}

TEST(TagPoseEstimatorTest, BadCornersAndCamerasAreRefused) {
  const TagPoseEstimator estimator;
  auto corners = Project(TagAt(2.0, 0.0), 0.16);
  PinholeRadTan no_focal = kCamera;
  no_focal.fx = 0.0;
  EXPECT_FALSE(estimator.Estimate(corners, no_focal).ok());
  auto nan = corners;
  nan[2].x() = std::numeric_limits<double>::quiet_NaN();
  EXPECT_NE(estimator.Estimate(nan, kCamera).status().message().find("not finite"), std::string::npos);
  std::array<Eigen::Vector2d, 4> line = {Eigen::Vector2d(10, 10), Eigen::Vector2d(20, 20), Eigen::Vector2d(30, 30),
                                         Eigen::Vector2d(40, 40)};
  EXPECT_NE(estimator.Estimate(line, kCamera).status().message().find("degenerate"), std::string::npos);
  TagPoseOptions no_size;
  no_size.tag_size = 0.0;
  EXPECT_FALSE(TagPoseEstimator(no_size).Estimate(corners, kCamera).ok());
}

}  // namespace
}  // namespace cairn
