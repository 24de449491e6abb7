#include "detection/gravity_agreement.h"

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace cairn {
namespace {

Eigen::Matrix3d Rot(double angle, const Eigen::Vector3d& axis) {
  return Eigen::AngleAxisd(angle, axis.normalized()).toRotationMatrix();
}

TEST(GravityAgreementTest, AConsistentSightingOfTiltedRobotsAgrees) {
  // a on a 10 deg slope, b on another, 20 deg yawed: the true relative rotation agrees exactly,
  // whatever the yaw (gravity says nothing about it).
  const Eigen::Matrix3d R_a = Rot(0.3, Eigen::Vector3d::UnitZ()) * Rot(0.17, Eigen::Vector3d(1, 1, 0));
  const Eigen::Matrix3d R_b = Rot(-1.2, Eigen::Vector3d::UnitZ()) * Rot(0.12, Eigen::Vector3d(0, 1, 0));
  const Eigen::Matrix3d R_a_b = R_a.transpose() * R_b;
  const Eigen::Matrix3d cov = Eigen::Matrix3d::Identity() * 0.02 * 0.02;
  const GravityAgreement g = GravityAgreementOf(R_a, R_b, R_a_b, cov, 0.01);
  EXPECT_NEAR(g.angle, 0.0, 1e-12);
  EXPECT_NEAR(g.mahalanobis2, 0.0, 1e-12);
  // The frames are gravity aligned, not yaw aligned: a common yaw of both frames changes nothing.
  const GravityAgreement yawed =
      GravityAgreementOf(R_a, Rot(0.7, Eigen::Vector3d::UnitZ()) * R_b, R_a_b, cov, 0.01);
  EXPECT_NEAR(yawed.angle, 0.0, 1e-12);
}

TEST(GravityAgreementTest, TiltErrorsCountInTheirSigmasAndYawErrorsNot) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  // Level robots: a tilt error of 0.05 rad with a 0.02 rad sigma is 2.5 sigma.
  GravityAgreement g = GravityAgreementOf(I, I, Rot(0.05, Eigen::Vector3d::UnitX()), I * 0.02 * 0.02, 0.0);
  EXPECT_NEAR(g.angle, 0.05, 1e-12);
  EXPECT_NEAR(g.mahalanobis2, 6.25, 0.05);  // first order in the error
  // Each robot's own attitude uncertainty adds: 0.02 rad against 2 x 0.01^2 of variance.
  g = GravityAgreementOf(I, I, Rot(0.02, Eigen::Vector3d::UnitY()), I * 1e-12, 0.01);
  EXPECT_NEAR(g.mahalanobis2, 2.0, 0.01);
  // A yaw error is no tilt error.
  g = GravityAgreementOf(I, I, Rot(1.0, Eigen::Vector3d::UnitZ()), I * 1e-6, 0.0);
  EXPECT_NEAR(g.angle, 0.0, 1e-12);
  EXPECT_NEAR(g.mahalanobis2, 0.0, 1e-9);
}

TEST(GravityAgreementTest, AFlippedSolutionIsFarOutAndUpsideDownIsInfinitelySo) {
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const double sigma = 3.0 * std::numbers::pi / 180;
  const GravityAgreement flip = GravityAgreementOf(
      I, I, Rot(103 * std::numbers::pi / 180, Eigen::Vector3d(1, 2, 0)), I * sigma * sigma, 0.01);
  EXPECT_NEAR(flip.angle, 103 * std::numbers::pi / 180, 1e-9);
  EXPECT_GT(flip.mahalanobis2, 300.0);
  const GravityAgreement upside_down =
      GravityAgreementOf(I, I, Rot(std::numbers::pi, Eigen::Vector3d::UnitX()), I * sigma * sigma, 0.01);
  EXPECT_TRUE(std::isinf(upside_down.mahalanobis2));
}

}  // namespace
}  // namespace cairn
