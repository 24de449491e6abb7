#pragma once
// A deterministic smooth 6-DoF trajectory in closed form: a sum of sinusoids per position axis and
// per ZYX Euler angle, with analytic velocity, acceleration and body angular velocity. A trajectory
// source like BSplineTrajectory, defined for every t, for filter tests and benchmarks.

#include "sim/bspline_trajectory.h"

namespace cairn::sim {

class AnalyticTrajectory {
 public:
  // `motion_scale` scales the motion's amplitudes; 0 holds one slightly tilted pose.
  explicit AnalyticTrajectory(double motion_scale = 1.0) : motion_scale_(motion_scale) {}

  TrajectoryState Evaluate(double t) const;

 private:
  double motion_scale_;
};

}  // namespace cairn::sim
