#include "estimation/filter/wheel_velocity.h"

#include <cmath>

#include <gtest/gtest.h>

#include "estimation/filter/local_reference_filter.h"

namespace cairn {
namespace {

WheelCalibration FourWheels() {
  WheelCalibration c;
  c.wheel_count = 4;
  c.p_body_wheel = {Eigen::Vector2d(0.4, 0.3), Eigen::Vector2d(0.4, -0.3), Eigen::Vector2d(-0.4, 0.3),
                    Eigen::Vector2d(-0.4, -0.3)};
  c.speed_noise = 0.01;
  return c;
}

// Wheel readings of a rigid body moving with (vx, vy, wz), each wheel steered along its motion.
WheelOdometrySample Rigid(const WheelCalibration& c, double vx, double vy, double wz) {
  WheelOdometrySample s;
  s.time = Timestamp::FromSeconds(3.0);
  s.wheel_count = static_cast<uint8_t>(c.wheel_count);
  for (int i = 0; i < c.wheel_count; ++i) {
    const Eigen::Vector2d& p = c.p_body_wheel[static_cast<size_t>(i)];
    const Eigen::Vector2d v(vx - wz * p.y(), vy + wz * p.x());
    s.wheels[static_cast<size_t>(i)] = {v.norm(), std::atan2(v.y(), v.x())};
  }
  return s;
}

TEST(WheelVelocityTest, RecoversRigidBodyVelocity) {
  const WheelCalibration c = FourWheels();
  BodyVelocity v;
  ASSERT_TRUE(WheelBodyVelocity(Rigid(c, 0.5, 0.1, 0.2), c, 0.05, &v));
  EXPECT_NEAR(v.v_xy.x(), 0.5, 1e-9);
  EXPECT_NEAR(v.v_xy.y(), 0.1, 1e-9);
  EXPECT_EQ(v.time, Timestamp::FromSeconds(3.0));
  // Four wheels average the per-wheel noise.
  EXPECT_LT(v.covariance(0, 0), 0.01 * 0.01);
  EXPECT_GT(v.covariance(0, 0), 0.0);
}

TEST(WheelVelocityTest, SkidSteerWithoutSteeringConstrainsSideSlip) {
  const WheelCalibration c = FourWheels();
  WheelOdometrySample s = Rigid(c, 0.3, 0.0, 0.0);
  BodyVelocity v;
  ASSERT_TRUE(WheelBodyVelocity(s, c, 0.05, &v));
  EXPECT_NEAR(v.v_xy.x(), 0.3, 1e-9);
  EXPECT_NEAR(v.v_xy.y(), 0.0, 1e-9);
  // Lateral velocity is known only through the no-side-slip assumption.
  EXPECT_GT(v.covariance(1, 1), v.covariance(0, 0));
}

TEST(WheelVelocityTest, RejectsTooFewWheelsAndBadValues) {
  WheelCalibration c = FourWheels();
  WheelOdometrySample s = Rigid(c, 0.3, 0.0, 0.0);
  BodyVelocity v;
  s.wheel_count = 1;
  EXPECT_FALSE(WheelBodyVelocity(s, c, 0.05, &v));
  s.wheel_count = 4;
  s.wheels[2].speed = std::nan("");
  EXPECT_FALSE(WheelBodyVelocity(s, c, 0.05, &v));
}

TEST(WheelVelocityTest, FilterTakesWheelSamples) {
  const WheelCalibration c = FourWheels();
  FilterOptions o;
  o.wheel_enabled = true;
  ImuCalibration imu;
  imu.gyro_noise_density = 1e-4;
  imu.accel_noise_density = 1e-3;
  imu.gyro_random_walk = 1e-5;
  imu.accel_random_walk = 1e-4;
  LocalReferenceFilter f(o, imu, c);
  ImuSample first;
  first.time = Timestamp::FromSeconds(3.0);
  first.accel = Eigen::Vector3d(0, 0, 9.81);
  f.Initialize(first.time, Eigen::Vector3d::Zero(), Eigen::Vector3d(0.1, 0, 0), Eigen::Quaterniond::Identity(),
               Eigen::Vector3d::Zero(), Eigen::Vector3d::Zero(), Eigen::Matrix<double, 15, 15>::Identity() * 0.01,
               first);
  EXPECT_EQ(f.ApplyWheelOdometry(Rigid(c, 0.5, 0.0, 0.0)), FilterResult::kApplied);
  EXPECT_GT(f.state().v.x(), 0.45);  // the velocity moved to the wheel measurement
  WheelOdometrySample bad = Rigid(c, 0.5, 0.0, 0.0);
  bad.wheel_count = 1;
  EXPECT_EQ(f.ApplyWheelOdometry(bad), FilterResult::kRejectedInvalid);
}

}  // namespace
}  // namespace cairn
