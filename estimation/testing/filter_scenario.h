#pragma once
// A simulated run of the local reference filter for tests and benchmarks: IMU samples from
// ImuSimulator, clones at camera triggers between samples, noisy relative poses from a keyframe
// clone to the current clone delivered after a delay, optional wheel velocities and periodic frame
// switches. The truth is tracked in the filter's current frame so that errors can be evaluated.

#include <cstdint>
#include <deque>
#include <functional>
#include <memory>
#include <random>

#include "estimation/testing/filter_test_util.h"

namespace cairn::testing {

struct ScenarioOptions {
  double duration = 10.0;       // s
  double camera_rate = 20.0;    // Hz; 0 = no clones
  double trigger_offset = 0.0013;  // s after each multiple of the camera period
  int keyframe_lag = 4;         // relative pose from clone (c - lag) to clone c
  double update_delay = 0.0;    // s from exposure to delivery
  double updates_until = 1e9;   // s; no relative poses for later exposures
  double wheel_rate = 0.0;      // Hz; 0 = none
  double switch_period = 0.0;   // s; 0 = never
  double sigma_t = 0.01;        // m, relative translation noise
  double sigma_r = 0.003;       // rad, relative rotation noise
  double motion_scale = 1.0;
  uint64_t seed = 1;
};

struct ScenarioHooks {
  // Called after every IMU sample with the truth in the filter's current frame.
  std::function<void(const LocalReferenceFilter&, const TrajectoryPoint& truth_in_frame)> after_sample;
};

class FilterScenario {
 public:
  FilterScenario(const ScenarioOptions& options, const FilterOptions& filter_options);

  // Runs to the end; `filter()` keeps the final state.
  void Run(const ScenarioHooks& hooks = {});
  // Single steps, for benchmarks: returns false at the end. Timed phases are reported through
  // the callbacks (kind 0 IMU, 1 relative pose, 2 wheel, 3 frame switch).
  bool Step(const std::function<void(int kind, double seconds)>& timed = {});
  LocalReferenceFilter& filter() { return *filter_; }
  const TrajectoryPoint& truth_in_frame() const { return truth_in_frame_; }

 private:
  struct PendingMeasurement {
    Timestamp arrival;
    CloneId keyframe, current;
    Eigen::Isometry3d T;
  };
  TrajectoryPoint ToFrame(const TrajectoryPoint& w) const;

  ScenarioOptions options_;
  ImuSimulator sim_;
  std::unique_ptr<LocalReferenceFilter> filter_;
  std::mt19937_64 rng_;
  Matrix6d rel_cov_;
  Eigen::Isometry3d T_world_frame_ = Eigen::Isometry3d::Identity();
  TrajectoryPoint truth_in_frame_;
  int64_t next_trigger_ = 1;
  int64_t next_wheel_ = 1;
  int64_t next_switch_ = 1;
  std::deque<std::pair<CloneId, TrajectoryPoint>> clones_;
  std::deque<PendingMeasurement> pending_;
  bool done_ = false;
};

}  // namespace cairn::testing
