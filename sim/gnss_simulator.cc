#include "sim/gnss_simulator.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "common/angles.h"
#include "sim/sim_random.h"

namespace cairn::sim {
namespace {

constexpr uint64_t kGnssStreamBase = 0x6E55;  // SimRandom streams of the GNSS receivers
constexpr int kGnssSatellites = 12;
// Total per-axis sigma below which the solution counts as RTK fixed.
constexpr double kGnssRtkSigma = 0.05;  // m
// No receiver states a zero accuracy, and a consumer inverts the covariance.
constexpr double kGnssMinSigma = 0.001;  // m

double GnssExponential(SimRandom& rng, double mean) { return -mean * std::log(1.0 - rng.Uniform()); }

Eigen::Vector3d GnssNormal3(SimRandom& rng) {
  const double e = rng.Normal(), n = rng.Normal(), u = rng.Normal();
  return {e, n, u};
}

}  // namespace

GnssSimulator::GnssSimulator(const GnssSimulatorOptions& options, uint64_t seed, uint64_t stream)
    : options_(options),
      seed_(seed),
      stream_(stream),
      plane_({options.origin_latitude * kDegree, options.origin_longitude * kDegree, options.origin_height}),
      lever_arm_(options.antenna_x, options.antenna_y, options.antenna_z) {
  const double b2 = options.bias_sigma * options.bias_sigma;
  const double h2 =
      std::max(options.sigma_horizontal * options.sigma_horizontal + b2, kGnssMinSigma * kGnssMinSigma);
  const double v2 =
      std::max(options.sigma_vertical * options.sigma_vertical + b2, kGnssMinSigma * kGnssMinSigma);
  covariance_ = Eigen::Vector3d(h2, h2, v2).asDiagonal();
  quality_ =
      std::max(h2, v2) < kGnssRtkSigma * kGnssRtkSigma ? GnssQuality::kRtkFixed : GnssQuality::kAutonomous;
}

std::vector<GnssTruth> GnssSimulator::Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                               double duration) const {
  const GnssSimulatorOptions& o = options_;
  const int64_t period_ns = std::llround(1e9 / o.rate_hz);
  const int64_t count = static_cast<int64_t>(std::floor(duration * o.rate_hz + 1e-9)) + 1;
  const Timestamp end = start + Duration::Seconds(duration);
  const Duration latency = Duration::Seconds(o.latency);
  const double phi = std::exp(-static_cast<double>(period_ns) * 1e-9 / o.bias_time_constant);
  const double drive = o.bias_sigma * std::sqrt(1.0 - phi * phi);
  const Eigen::Vector3d white(o.sigma_horizontal, o.sigma_horizontal, o.sigma_vertical);
  // Separate streams: outage settings do not change the noise of the fixes that remain.
  SimRandom noise = SimRandom::Stream(seed_, kGnssStreamBase + stream_, 0);
  SimRandom gaps = SimRandom::Stream(seed_, kGnssStreamBase + stream_, 1);
  constexpr double kNever = std::numeric_limits<double>::infinity();
  const auto next_outage = [&](double after) {
    return o.outage_rate > 0.0 ? after + GnssExponential(gaps, 1.0 / o.outage_rate) : kNever;
  };
  double outage_begin = next_outage(0.0);
  double outage_end =
      outage_begin + (outage_begin < kNever ? GnssExponential(gaps, o.outage_mean_duration) : 0.0);

  Eigen::Vector3d bias = o.bias_sigma * GnssNormal3(noise);  // the steady state
  std::vector<GnssTruth> out;
  out.reserve(static_cast<size_t>(count));
  for (int64_t k = 0; k < count; ++k) {
    // Drawn for every epoch, in or out of an outage: an epoch's error does not depend on outages.
    const Eigen::Vector3d error = white.cwiseProduct(GnssNormal3(noise)) + bias;
    bias = phi * bias + drive * GnssNormal3(noise);
    // Times from integer nanoseconds, as the other sensors' (a fix at 1 Hz falls on an IMU sample).
    const Duration since = Duration::Nanoseconds(k * period_ns);
    const double t = since.seconds();
    while (t >= outage_end) {
      outage_begin = next_outage(outage_end);
      outage_end = outage_begin + GnssExponential(gaps, o.outage_mean_duration);
    }
    GnssTruth truth;
    truth.fix.time = start + since;
    truth.published = truth.fix.time + latency;
    if (t >= outage_begin || truth.published > end) continue;
    truth.p_world_antenna = trajectory.Evaluate(t).T_world_body * lever_arm_;
    // The error is in the axes at the antenna, as the receiver states its accuracy.
    const Eigen::Matrix3d R_world_local = plane_.R_datum_local(plane_.ToGeodetic(truth.p_world_antenna));
    const GeodeticPoint g = plane_.ToGeodetic(truth.p_world_antenna + R_world_local * error);
    truth.fix.latitude = g.latitude;
    truth.fix.longitude = g.longitude;
    truth.fix.height = g.height;
    truth.fix.covariance = covariance_;
    truth.fix.quality = quality_;
    truth.fix.satellites = kGnssSatellites;
    out.push_back(truth);
  }
  return out;
}

}  // namespace cairn::sim
