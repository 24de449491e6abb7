#pragma once
// A smooth (C2) 6-DoF trajectory: uniform cubic B-splines over position and over ZYX Euler angles
// (yaw, pitch, roll). Velocity, acceleration and body angular velocity are analytic derivatives,
// so a simulated IMU is exactly consistent with the ground-truth poses.

#include <vector>

#include <Eigen/Core>
#include <Eigen/Geometry>

namespace cairn::sim {

struct TrajectoryState {
  Eigen::Isometry3d T_world_body = Eigen::Isometry3d::Identity();
  Eigen::Vector3d velocity = Eigen::Vector3d::Zero();       // world frame
  Eigen::Vector3d acceleration = Eigen::Vector3d::Zero();   // world frame
  Eigen::Vector3d omega_body = Eigen::Vector3d::Zero();     // body frame angular velocity
};

class BSplineTrajectory {
 public:
  BSplineTrajectory() = default;
  // Control points every `knot_interval` seconds; `euler` holds (yaw, pitch, roll) unwrapped.
  // The curve is defined on [0, (n - 3) * knot_interval].
  BSplineTrajectory(double knot_interval, std::vector<Eigen::Vector3d> positions,
                    std::vector<Eigen::Vector3d> euler);

  double duration() const;
  TrajectoryState Evaluate(double t) const;

  // R = Rz(yaw) Ry(pitch) Rx(roll).
  static Eigen::Matrix3d EulerToRotation(const Eigen::Vector3d& ypr);

 private:
  double dt_ = 1.0;
  std::vector<Eigen::Vector3d> p_;
  std::vector<Eigen::Vector3d> e_;
};

}  // namespace cairn::sim
