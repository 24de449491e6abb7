#include "drivers/replay/recorded_calibration.h"

#include <cmath>

#include "cairn/calibration.pb.h"

namespace cairn {
namespace {

void ToRigid(const Eigen::Isometry3d& T, msg::Rigid3* out) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) out->add_rows(T.matrix()(r, c));
  }
}

Expected<Eigen::Isometry3d> FromRigid(const msg::Rigid3& m, const std::string& where) {
  if (m.rows_size() != 12) {
    return DataLossError(where + ": transform has " + std::to_string(m.rows_size()) + " values, expected 12");
  }
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 4; ++c) {
      const double v = m.rows(r * 4 + c);
      if (!std::isfinite(v)) return DataLossError(where + ": transform holds a non-finite value");
      T.matrix()(r, c) = v;
    }
  }
  const Eigen::Matrix3d R = T.linear();
  // Stored at full precision, so a rotation off by more than rounding was never one.
  if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-9 || R.determinant() < 0.0) {
    return DataLossError(where + ": transform rotation is not orthonormal");
  }
  return T;
}

void ToCamera(const CameraCalibration& cam, msg::PinholeCamera* out) {
  const PinholeRadTan& k = cam.intrinsics;
  out->set_name(cam.name);
  out->set_width(static_cast<uint32_t>(k.width));
  out->set_height(static_cast<uint32_t>(k.height));
  out->set_fx(k.fx);
  out->set_fy(k.fy);
  out->set_cx(k.cx);
  out->set_cy(k.cy);
  out->set_k1(k.k1);
  out->set_k2(k.k2);
  out->set_p1(k.p1);
  out->set_p2(k.p2);
  ToRigid(cam.T_body_cam, out->mutable_t_body_cam());
}

Expected<CameraCalibration> FromCamera(const msg::PinholeCamera& m, const std::string& where) {
  CameraCalibration cam;
  cam.name = m.name();
  PinholeRadTan& k = cam.intrinsics;
  if (m.width() == 0 || m.height() == 0 || m.width() > 65536 || m.height() > 65536) {
    return DataLossError(where + ": image size " + std::to_string(m.width()) + "x" + std::to_string(m.height()) +
                         " is not a camera's");
  }
  k.width = static_cast<int>(m.width());
  k.height = static_cast<int>(m.height());
  k.fx = m.fx();
  k.fy = m.fy();
  k.cx = m.cx();
  k.cy = m.cy();
  k.k1 = m.k1();
  k.k2 = m.k2();
  k.p1 = m.p1();
  k.p2 = m.p2();
  for (double v : {k.fx, k.fy, k.cx, k.cy, k.k1, k.k2, k.p1, k.p2}) {
    if (!std::isfinite(v)) return DataLossError(where + ": intrinsics hold a non-finite value");
  }
  if (!(k.fx > 0.0) || !(k.fy > 0.0)) return DataLossError(where + ": focal lengths must be positive");
  auto T = FromRigid(m.t_body_cam(), where + " T_body_cam");
  if (!T.ok()) return T.status();
  cam.T_body_cam = *T;
  return cam;
}

}  // namespace

std::string RecordedCalibration::Encode() const {
  msg::Calibration m;
  m.set_robot(robot);
  ToCamera(stereo.left, m.mutable_left());
  ToCamera(stereo.right, m.mutable_right());
  m.set_camera_rate_hz(camera_rate_hz);
  msg::Imu* i = m.mutable_imu();
  ToRigid(imu.T_body_imu, i->mutable_t_body_imu());
  i->set_rate_hz(imu.rate_hz);
  i->set_gyro_noise_density(imu.gyro_noise_density);
  i->set_gyro_random_walk(imu.gyro_random_walk);
  i->set_accel_noise_density(imu.accel_noise_density);
  i->set_accel_random_walk(imu.accel_random_walk);
  if (wheels) {
    msg::Wheels* w = m.mutable_wheels();
    for (int k = 0; k < wheels->wheel_count; ++k) {
      msg::WheelContact* c = w->add_contacts();
      c->set_x(wheels->p_body_wheel[static_cast<size_t>(k)].x());
      c->set_y(wheels->p_body_wheel[static_cast<size_t>(k)].y());
    }
    w->set_speed_noise(wheels->speed_noise);
  }
  return m.SerializeAsString();
}

Expected<RecordedCalibration> RecordedCalibration::Decode(std::span<const uint8_t> bytes, const std::string& where) {
  msg::Calibration m;
  if (!m.ParseFromArray(bytes.data(), static_cast<int>(bytes.size()))) {
    return DataLossError(where + ": calibration message does not decode");
  }
  if (!m.has_left() || !m.has_right() || !m.has_imu()) {
    return DataLossError(where + ": calibration lacks the left camera, the right camera or the IMU");
  }
  RecordedCalibration c;
  c.robot = m.robot();
  auto left = FromCamera(m.left(), where + " left camera");
  if (!left.ok()) return left.status();
  auto right = FromCamera(m.right(), where + " right camera");
  if (!right.ok()) return right.status();
  c.stereo.left = *left;
  c.stereo.right = *right;
  if (!(m.camera_rate_hz() > 0.0) || !std::isfinite(m.camera_rate_hz())) {
    return DataLossError(where + ": camera rate must be positive");
  }
  c.camera_rate_hz = m.camera_rate_hz();
  const msg::Imu& i = m.imu();
  auto T = FromRigid(i.t_body_imu(), where + " T_body_imu");
  if (!T.ok()) return T.status();
  c.imu.T_body_imu = *T;
  c.imu.rate_hz = i.rate_hz();
  c.imu.gyro_noise_density = i.gyro_noise_density();
  c.imu.gyro_random_walk = i.gyro_random_walk();
  c.imu.accel_noise_density = i.accel_noise_density();
  c.imu.accel_random_walk = i.accel_random_walk();
  for (double v : {c.imu.rate_hz, c.imu.gyro_noise_density, c.imu.gyro_random_walk, c.imu.accel_noise_density,
                   c.imu.accel_random_walk}) {
    if (!(v > 0.0) || !std::isfinite(v)) {
      return DataLossError(where + ": IMU rate and noise figures must be positive");
    }
  }
  if (m.has_wheels()) {
    const msg::Wheels& w = m.wheels();
    if (w.contacts_size() == 0 || w.contacts_size() > kMaxWheels) {
      return DataLossError(where + ": " + std::to_string(w.contacts_size()) + " wheels, expected 1 to " +
                           std::to_string(kMaxWheels));
    }
    WheelCalibration wheels;
    wheels.wheel_count = w.contacts_size();
    for (int k = 0; k < w.contacts_size(); ++k) {
      const double x = w.contacts(k).x(), y = w.contacts(k).y();
      if (!std::isfinite(x) || !std::isfinite(y)) return DataLossError(where + ": wheel contact is not finite");
      wheels.p_body_wheel[static_cast<size_t>(k)] = {x, y};
    }
    if (!(w.speed_noise() >= 0.0) || !std::isfinite(w.speed_noise())) {
      return DataLossError(where + ": wheel speed noise must be finite and not negative");
    }
    wheels.speed_noise = w.speed_noise();
    c.wheels = wheels;
  }
  return c;
}

}  // namespace cairn
