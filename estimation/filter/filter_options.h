#pragma once
// Options of the local reference filter (estimation/filter/local_reference_filter.h). Capacities are
// fixed at construction; nothing is resized afterwards.

#include <cstdint>

#include "common/options_visitor.h"
#include "estimation/filter/filter_state.h"

namespace cairn {

inline constexpr int64_t kMaxImuBuffer = 4096;
inline constexpr int64_t kMaxEventLog = 1024;
inline constexpr int64_t kMaxSnapshots = 64;
inline constexpr int64_t kMaxHistory = 8192;

struct FilterOptions {
  double gravity = 9.81;  // m/s^2, local gravity magnitude

  // Clones and delayed updates.
  int64_t max_clones = kMaxClones;
  // Late measurements up to this age are applied exactly by re-propagation (bounds replay work).
  double max_update_delay = 0.5;  // s
  // Clones, wheel and position measurements further ahead of the newest IMU sample are rejected.
  double max_event_lead = 1.0;  // s
  int64_t imu_buffer = 1024;    // samples kept for re-propagation
  int64_t event_log = 256;      // clone/update/wheel events kept for re-propagation
  int64_t snapshots = 24;       // states kept at clone times (replay starting points)
  int64_t history = 2048;       // IMU-rate poses kept for PoseAt()

  // IMU sample screening.
  double max_imu_gap = 0.1;  // s; a larger step is treated as a far-future (bad) time stamp
  // After this many consecutive samples that all lie beyond max_imu_gap but are in order among
  // themselves, the gap is accepted as real: the filter restarts its integration at the new time
  // and adds the gap's process noise.
  int64_t imu_resync_samples = 50;

  // Static initialization.
  double init_duration = 1.0;        // s of still IMU data averaged
  double init_block = 0.1;           // s; samples averaged before the stillness checks
  double init_max_gyro = 0.2;        // rad/s; larger rates (beyond any plausible bias) are motion
  double init_max_gyro_dev = 0.01;   // rad/s; deviation from the window's mean rate
  double init_max_accel_dev = 0.1;   // m/s^2; deviation from the window mean and of |a| from g
  // m/s; wheels reporting a faster body speed (and one well outside its noise) restart the still
  // window: driving at constant speed looks still to the IMU.
  double init_max_wheel_speed = 0.02;
  double init_sigma_roll_pitch = 0.01;  // rad
  double init_sigma_velocity = 0.02;    // m/s
  double init_sigma_accel_bias = 0.1;   // m/s^2
  double init_sigma_gyro_bias = 0.002;  // rad/s (after averaging a still window)

  // Wheel odometry.
  bool wheel_enabled = false;
  // Side slip of each wheel assumed zero with this sigma when wheel speeds are turned into a body
  // velocity.
  double wheel_lateral_sigma = 0.05;  // m/s
  // Rover profiles: body z velocity is zero (non-holonomic pseudo-measurement).
  bool nonholonomic = false;
  double nonholonomic_sigma = 0.05;  // m/s

  // Mahalanobis gate on relative-pose innovations (chi-square, 6 DOF); 0 disables it.
  double relative_pose_gate = 0.0;

  void Visit(OptionsVisitor& v) {
    v.Number("gravity", gravity, 9.7, 9.9, "m/s^2");
    v.Integer("max_clones", max_clones, 2, kMaxClones, "clones");
    v.Number("max_update_delay", max_update_delay, 0.0, 5.0, "s");
    v.Number("max_event_lead", max_event_lead, 0.0, 10.0, "s");
    v.Integer("imu_buffer", imu_buffer, 16, kMaxImuBuffer, "samples");
    v.Integer("event_log", event_log, 16, kMaxEventLog, "events");
    v.Integer("snapshots", snapshots, 2, kMaxSnapshots, "states");
    v.Integer("history", history, 2, kMaxHistory, "samples");
    v.Number("max_imu_gap", max_imu_gap, 1e-4, 10.0, "s");
    v.Integer("imu_resync_samples", imu_resync_samples, 1, 100000, "samples");
    v.Number("init_duration", init_duration, 0.01, 60.0, "s");
    v.Number("init_block", init_block, 0.0, 5.0, "s");
    v.Number("init_max_gyro", init_max_gyro, 0.0, 10.0, "rad/s");
    v.Number("init_max_gyro_dev", init_max_gyro_dev, 0.0, 10.0, "rad/s");
    v.Number("init_max_accel_dev", init_max_accel_dev, 0.0, 20.0, "m/s^2");
    v.Number("init_max_wheel_speed", init_max_wheel_speed, 0.0, 10.0, "m/s");
    v.Number("init_sigma_roll_pitch", init_sigma_roll_pitch, 1e-6, 1.0, "rad");
    v.Number("init_sigma_velocity", init_sigma_velocity, 1e-6, 10.0, "m/s");
    v.Number("init_sigma_accel_bias", init_sigma_accel_bias, 1e-6, 10.0, "m/s^2");
    v.Number("init_sigma_gyro_bias", init_sigma_gyro_bias, 1e-7, 1.0, "rad/s");
    v.Flag("wheel_enabled", wheel_enabled);
    v.Number("wheel_lateral_sigma", wheel_lateral_sigma, 1e-4, 10.0, "m/s");
    v.Flag("nonholonomic", nonholonomic);
    v.Number("nonholonomic_sigma", nonholonomic_sigma, 1e-4, 10.0, "m/s");
    v.Number("relative_pose_gate", relative_pose_gate, 0.0, 1e6, "chi-square");
  }

  Status Validate() const {
    if (nonholonomic && !wheel_enabled) {
      return InvalidArgumentError("filter.nonholonomic needs filter.wheel_enabled");
    }
    return Status::Ok();
  }
};

}  // namespace cairn
