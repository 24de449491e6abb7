#include "mapping/matching/four_dof_transform.h"

#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

namespace cairn {
namespace {

Eigen::Isometry3d Isometry(double x, double y, double z, double yaw, double pitch, double roll) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() =
      (Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()) * Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()) *
       Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()))
          .toRotationMatrix();
  T.translation() = Eigen::Vector3d(x, y, z);
  return T;
}

TEST(FourDofTransformTest, WrapAngleMapsIntoHalfOpenInterval) {
  EXPECT_DOUBLE_EQ(WrapAngle(0.3), 0.3);
  EXPECT_DOUBLE_EQ(WrapAngle(std::numbers::pi), std::numbers::pi);
  EXPECT_DOUBLE_EQ(WrapAngle(-std::numbers::pi), std::numbers::pi);
  EXPECT_NEAR(WrapAngle(3.0 * std::numbers::pi / 2.0), -std::numbers::pi / 2.0, 1e-15);
  EXPECT_NEAR(WrapAngle(-7.0), -7.0 + 2.0 * std::numbers::pi, 1e-15);
  EXPECT_NEAR(WrapAngle(20.0), 20.0 - 6.0 * std::numbers::pi, 1e-14);
}

TEST(FourDofTransformTest, IsometryRoundTripAndPointMapping) {
  const FourDofTransform T(1.0, -2.0, 0.5, 2.5);
  const Eigen::Isometry3d iso = T.ToIsometry();
  const Eigen::Vector3d p(0.3, 4.0, -1.0);
  EXPECT_LT(((iso * p) - (T * p)).norm(), 1e-12);
  const Expected<FourDofTransform> back = FourDofTransform::FromIsometry(iso);
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_LT((back->ToVector() - T.ToVector()).norm(), 1e-12);
  EXPECT_NEAR(FourDofTransform::TiltOf(iso.linear()), 0.0, 1e-15);
}

TEST(FourDofTransformTest, CompositionAndInverseMatchIsometries) {
  const FourDofTransform T_a_b(1.0, 2.0, 3.0, 3.0);
  const FourDofTransform T_b_c(-0.5, 0.25, -1.0, 1.0);  // yaws add past pi: wrapped
  const FourDofTransform T_a_c = T_a_b * T_b_c;
  const Eigen::Isometry3d expected = T_a_b.ToIsometry() * T_b_c.ToIsometry();
  EXPECT_LT((T_a_c.ToIsometry().matrix() - expected.matrix()).norm(), 1e-12);
  EXPECT_NEAR(T_a_c.yaw(), 4.0 - 2.0 * std::numbers::pi, 1e-12);
  const FourDofTransform identity = T_a_b * T_a_b.inverse();
  EXPECT_LT(identity.translation().norm(), 1e-12);
  EXPECT_NEAR(identity.yaw(), 0.0, 1e-12);
  EXPECT_LT((T_a_b.inverse().ToIsometry().matrix() - T_a_b.ToIsometry().inverse().matrix()).norm(), 1e-12);
}

TEST(FourDofTransformTest, TiltBeyondToleranceIsRefusedAndReported) {
  const Eigen::Isometry3d tilted = Isometry(1.0, 2.0, 3.0, 0.7, 0.02, -0.01);
  const Expected<FourDofTransform> strict = FourDofTransform::FromIsometry(tilted, 1e-3);
  ASSERT_FALSE(strict.ok());
  EXPECT_EQ(strict.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(strict.status().message().find("tilted"), std::string::npos) << strict.status().message();
  const Expected<FourDofTransform> loose = FourDofTransform::FromIsometry(tilted, 0.05);
  ASSERT_TRUE(loose.ok());
  EXPECT_NEAR(loose->yaw(), 0.7, 1e-12);  // z-y-x Euler yaw
  double tilt = 0.0;
  FourDofTransform::ProjectIsometry(tilted, &tilt);
  EXPECT_NEAR(tilt, std::acos(std::cos(0.02) * std::cos(0.01)), 1e-12);
}

TEST(FourDofTransformTest, NonRotationsAndNonFiniteValuesAreRefused) {
  Eigen::Isometry3d scaled = Eigen::Isometry3d::Identity();
  scaled.linear() *= 1.1;
  EXPECT_EQ(FourDofTransform::FromIsometry(scaled).status().code(), StatusCode::kInvalidArgument);
  Eigen::Isometry3d mirrored = Eigen::Isometry3d::Identity();
  mirrored.linear()(0, 0) = -1.0;
  EXPECT_EQ(FourDofTransform::FromIsometry(mirrored).status().code(), StatusCode::kInvalidArgument);
  Eigen::Isometry3d nan = Eigen::Isometry3d::Identity();
  nan.translation().x() = std::nan("");
  EXPECT_EQ(FourDofTransform::FromIsometry(nan).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace cairn
