#include "drivers/replay/recorded_calibration.h"

#include <cmath>
#include <cstring>
#include <limits>

#include <gtest/gtest.h>

#include "cairn/calibration.pb.h"

namespace cairn {
namespace {

std::span<const uint8_t> Bytes(const std::string& s) {
  return {reinterpret_cast<const uint8_t*>(s.data()), s.size()};
}

bool SameBits(double a, double b) { return std::memcmp(&a, &b, sizeof(double)) == 0; }

RecordedCalibration Example() {
  RecordedCalibration c;
  c.robot = "rover1";
  c.camera_rate_hz = 10.0;
  for (CameraCalibration* cam : {&c.stereo.left, &c.stereo.right}) {
    cam->intrinsics = PinholeRadTan{1024, 508, 1080.0 + 1.0 / 3.0, 1079.5, 511.7, 253.9, -0.28, 0.07, 1e-4, -2e-5};
  }
  c.stereo.left.name = "cam0";
  c.stereo.right.name = "cam1";
  // A rotation whose entries need every bit of a double: re-orthonormalizing would change them.
  const Eigen::Quaterniond q = Eigen::Quaterniond(0.4, 0.5, -0.6, 0.3).normalized();
  c.stereo.left.T_body_cam.linear() = q.toRotationMatrix();
  c.stereo.left.T_body_cam.translation() = Eigen::Vector3d(0.1, -0.045, 0.7);
  c.stereo.right.T_body_cam = c.stereo.left.T_body_cam * Eigen::Translation3d(0.09, 0.0, 0.0);
  c.imu.T_body_imu.translation() = Eigen::Vector3d(0.01, 0.02, 0.03);
  c.imu.rate_hz = 200.0;
  c.imu.gyro_noise_density = 1.7e-4;
  c.imu.gyro_random_walk = 1.9e-5;
  c.imu.accel_noise_density = 2.0e-3;
  c.imu.accel_random_walk = 3.0e-3;
  WheelCalibration w;
  w.wheel_count = 4;
  w.p_body_wheel = {Eigen::Vector2d(0.4, 0.3), Eigen::Vector2d(0.4, -0.3), Eigen::Vector2d(-0.4, 0.3),
                    Eigen::Vector2d(-0.4, -0.3)};
  w.speed_noise = 0.02;
  c.wheels = w;
  return c;
}

TEST(RecordedCalibrationTest, RoundTripKeepsEveryBit) {
  const RecordedCalibration c = Example();
  auto d = RecordedCalibration::Decode(Bytes(c.Encode()), "test");
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  EXPECT_EQ(d->robot, "rover1");
  EXPECT_EQ(d->stereo.left.name, "cam0");
  EXPECT_EQ(d->stereo.right.intrinsics.width, 1024);
  EXPECT_TRUE(SameBits(d->stereo.left.intrinsics.fx, c.stereo.left.intrinsics.fx));
  EXPECT_TRUE(SameBits(d->stereo.right.intrinsics.p2, c.stereo.right.intrinsics.p2));
  for (int i = 0; i < 16; ++i) {
    EXPECT_TRUE(SameBits(d->stereo.left.T_body_cam.matrix().data()[i], c.stereo.left.T_body_cam.matrix().data()[i]));
    EXPECT_TRUE(SameBits(d->stereo.right.T_body_cam.matrix().data()[i], c.stereo.right.T_body_cam.matrix().data()[i]));
    EXPECT_TRUE(SameBits(d->imu.T_body_imu.matrix().data()[i], c.imu.T_body_imu.matrix().data()[i]));
  }
  EXPECT_TRUE(SameBits(d->imu.accel_random_walk, c.imu.accel_random_walk));
  EXPECT_EQ(d->camera_rate_hz, 10.0);
  ASSERT_TRUE(d->wheels.has_value());
  EXPECT_EQ(d->wheels->wheel_count, 4);
  EXPECT_EQ(d->wheels->p_body_wheel[3], Eigen::Vector2d(-0.4, -0.3));
  EXPECT_EQ(d->wheels->speed_noise, 0.02);
}

TEST(RecordedCalibrationTest, RobotsWithoutWheelsStayWithout) {
  RecordedCalibration c = Example();
  c.wheels.reset();
  auto d = RecordedCalibration::Decode(Bytes(c.Encode()), "test");
  ASSERT_TRUE(d.ok()) << d.status().ToString();
  EXPECT_FALSE(d->wheels.has_value());
}

void ExpectRefused(const msg::Calibration& m, const std::string& words) {
  auto d = RecordedCalibration::Decode(Bytes(m.SerializeAsString()), "rec.mcap /calibration");
  ASSERT_FALSE(d.ok()) << "accepted; expected: " << words;
  EXPECT_NE(d.status().message().find("rec.mcap /calibration"), std::string::npos) << d.status().message();
  EXPECT_NE(d.status().message().find(words), std::string::npos) << d.status().message();
}

TEST(RecordedCalibrationTest, ImpossibleCalibrationsAreRefusedNamingWhereAndWhat) {
  msg::Calibration good;
  ASSERT_TRUE(good.ParseFromString(Example().Encode()));
  {
    const std::string garbage = "\xff\xff\xff\xff not protobuf";
    auto d = RecordedCalibration::Decode(Bytes(garbage), "rec.mcap");
    EXPECT_FALSE(d.ok());
  }
  {
    msg::Calibration m = good;
    m.clear_right();
    ExpectRefused(m, "lacks");
  }
  {
    msg::Calibration m = good;
    m.mutable_left()->set_width(0);
    ExpectRefused(m, "left camera: image size 0x508");
  }
  {
    msg::Calibration m = good;
    m.mutable_right()->set_fx(std::numeric_limits<double>::quiet_NaN());
    ExpectRefused(m, "right camera: intrinsics hold a non-finite value");
  }
  {
    msg::Calibration m = good;
    m.mutable_left()->mutable_t_body_cam()->set_rows(0, 1.5);
    ExpectRefused(m, "not orthonormal");
  }
  {
    msg::Calibration m = good;
    m.mutable_imu()->mutable_t_body_imu()->mutable_rows()->RemoveLast();
    ExpectRefused(m, "T_body_imu: transform has 11 values");
  }
  {
    msg::Calibration m = good;
    m.mutable_imu()->set_rate_hz(0.0);
    ExpectRefused(m, "IMU rate");
  }
  {
    msg::Calibration m = good;
    m.set_camera_rate_hz(-1.0);
    ExpectRefused(m, "camera rate");
  }
  {
    msg::Calibration m = good;
    for (int i = 0; i < 2; ++i) *m.mutable_wheels()->add_contacts() = m.wheels().contacts(0);
    ExpectRefused(m, "6 wheels");
  }
}

}  // namespace
}  // namespace cairn
