#pragma once
// The GNSS fixes of an antenna on a simulated robot, as a receiver driver publishes them: WGS84
// positions of the antenna with white noise plus a slowly varying bias, dropped during outages,
// each published some latency after its measurement. The simulator's world frame is placed on the
// Earth with world x east, y north and z up at the options' origin.
//
// Errors are drawn in the east-north-up axes at the antenna, per axis:
//   e_k = w_k + b_k,  w_k ~ N(0, sigma^2)  (sigma_horizontal for east and north, sigma_vertical up)
//   b_{k+1} = phi b_k + sqrt(1 - phi^2) bias_sigma n_k,  phi = exp(-dt / bias_time_constant)
// b starts from its steady state N(0, bias_sigma^2) and runs through outages. The white part alone
// would let a filter average a bias away that a real receiver's errors, correlated over tens of
// seconds, never allow; the bias alone would hide the fix-to-fix jitter. The reported covariance
// is the receiver's stated accuracy, the total variance diag(sigma^2 + bias_sigma^2) per axis, as
// a receiver states its accuracy without telling how it is correlated.

#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/timestamp.h"
#include "estimation/math/local_tangent_plane.h"
#include "hal/gnss_fix.h"
#include "sim/bspline_trajectory.h"
#include "sim/gnss_simulator_options.h"

namespace cairn::sim {

struct GnssTruth {
  GnssFix fix;          // what the receiver reports
  Timestamp published;  // when it reports it: fix.time + latency
  // Where the antenna was at fix.time.
  Eigen::Vector3d p_world_antenna = Eigen::Vector3d::Zero();
};

class GnssSimulator {
 public:
  // `seed` is the mission's, `stream` tells the robots of one mission apart.
  GnssSimulator(const GnssSimulatorOptions& options, uint64_t seed, uint64_t stream);

  const LocalTangentPlane& plane() const { return plane_; }
  // Stated per-axis accuracy (m^2, east north up) and solution type of every fix.
  const Eigen::Matrix3d& covariance() const { return covariance_; }
  GnssQuality quality() const { return quality_; }

  // The fixes of measurement epochs t_k = k / rate_hz (k = 0, 1, ...) outside outages and published
  // by the end of the mission, `duration` s after `start` (trajectory time 0), in time order.
  std::vector<GnssTruth> Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                  double duration) const;

 private:
  GnssSimulatorOptions options_;
  uint64_t seed_, stream_;
  LocalTangentPlane plane_;
  Eigen::Vector3d lever_arm_;  // the antenna in the body frame
  Eigen::Matrix3d covariance_;
  GnssQuality quality_;
};

}  // namespace cairn::sim
