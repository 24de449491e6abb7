#include "sim/analytic_trajectory.h"

#include <cmath>

namespace cairn::sim {

TrajectoryState AnalyticTrajectory::Evaluate(double t) const {
  const double s = motion_scale_;
  TrajectoryState out;
  // Position: a sum of sinusoids per axis, amplitude a, frequency w, phase c.
  const double amp[3] = {2.0 * s, 1.5 * s, 0.3 * s};
  const double w[3] = {0.4, 0.55, 0.9};
  const double ph[3] = {0.0, 0.7, 1.3};
  for (int i = 0; i < 3; ++i) {
    out.T_world_body.translation()[i] = amp[i] * std::sin(w[i] * t + ph[i]);
    out.velocity[i] = amp[i] * w[i] * std::cos(w[i] * t + ph[i]);
    out.acceleration[i] = -amp[i] * w[i] * w[i] * std::sin(w[i] * t + ph[i]);
  }
  // Attitude: yaw, pitch, roll (ZYX) with their rates.
  const double yaw = 0.8 * s * std::sin(0.3 * t) + 0.3;
  const double yaw_d = 0.8 * s * 0.3 * std::cos(0.3 * t);
  const double pitch = 0.15 * s * std::sin(0.7 * t + 0.5) + 0.05;
  const double pitch_d = 0.15 * s * 0.7 * std::cos(0.7 * t + 0.5);
  const double roll = 0.2 * s * std::sin(0.9 * t + 1.1) - 0.08;
  const double roll_d = 0.2 * s * 0.9 * std::cos(0.9 * t + 1.1);
  const Eigen::Matrix3d Rz = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  const Eigen::Matrix3d Ry = Eigen::AngleAxisd(pitch, Eigen::Vector3d::UnitY()).toRotationMatrix();
  const Eigen::Matrix3d Rx = Eigen::AngleAxisd(roll, Eigen::Vector3d::UnitX()).toRotationMatrix();
  const Eigen::Matrix3d R = Rz * Ry * Rx;
  out.T_world_body.linear() = R;
  const Eigen::Vector3d omega_world = yaw_d * Eigen::Vector3d::UnitZ() +
                                      pitch_d * (Rz * Eigen::Vector3d::UnitY()) +
                                      roll_d * (Rz * Ry * Eigen::Vector3d::UnitX());
  out.omega_body = R.transpose() * omega_world;
  return out;
}

}  // namespace cairn::sim
