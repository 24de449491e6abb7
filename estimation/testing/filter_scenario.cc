#include "estimation/testing/filter_scenario.h"

#include "estimation/math/ordered_draws.h"

#include <chrono>
#include <cmath>

namespace cairn::testing {
namespace {

double Seconds(std::chrono::steady_clock::time_point a, std::chrono::steady_clock::time_point b) {
  return std::chrono::duration<double>(b - a).count();
}

ImuSimulatorOptions SimOptions(const ScenarioOptions& o) {
  ImuSimulatorOptions s;
  s.noise = TestNoise();
  s.seed = o.seed;
  s.motion_scale = o.motion_scale;
  s.initial_accel_bias = Eigen::Vector3d(0.05, -0.03, 0.08);
  s.initial_gyro_bias = Eigen::Vector3d(0.002, -0.001, 0.003);
  return s;
}

}  // namespace

FilterScenario::FilterScenario(const ScenarioOptions& options, const FilterOptions& filter_options)
    : options_(options),
      sim_(SimOptions(options)),
      filter_(std::make_unique<LocalReferenceFilter>(filter_options, TestCalibration())),
      rng_(options.seed * 7919 + 17) {
  rel_cov_.setZero();
  rel_cov_.diagonal() << Eigen::Vector3d::Constant(options.sigma_t * options.sigma_t),
      Eigen::Vector3d::Constant(options.sigma_r * options.sigma_r);
  StartFromTruth(sim_, *filter_, rng_);
  truth_in_frame_ = sim_.truth();
}

TrajectoryPoint FilterScenario::ToFrame(const TrajectoryPoint& w) const {
  TrajectoryPoint f = w;
  const Eigen::Matrix3d Rt = T_world_frame_.linear().transpose();
  f.p = Rt * (w.p - T_world_frame_.translation());
  f.v = Rt * w.v;
  f.a = Rt * w.a;
  f.q = Eigen::Quaterniond(Rt * w.q.toRotationMatrix());
  return f;
}

void FilterScenario::Run(const ScenarioHooks& hooks) {
  while (Step()) {
    if (hooks.after_sample) hooks.after_sample(*filter_, truth_in_frame_);
  }
}

bool FilterScenario::Step(const std::function<void(int, double)>& timed) {
  if (done_) return false;
  using Clock = std::chrono::steady_clock;
  const ImuSample s = sim_.Next();
  const double t = (s.time - sim_.TimeOf(0.0)).seconds();
  if (t > options_.duration) {
    done_ = true;
    return false;
  }
  // Triggers are announced just before the IMU sample that covers them.
  if (options_.camera_rate > 0.0) {
    const double trig = static_cast<double>(next_trigger_) / options_.camera_rate + options_.trigger_offset;
    if (trig <= t) {
      ++next_trigger_;
      const CloneRequest c = filter_->Clone(sim_.TimeOf(trig));
      if (c.id != kNoClone) {
        // Relative poses do not depend on the frame: keep world truth.
        clones_.emplace_back(c.id, sim_.Truth(trig));
        if (static_cast<int>(clones_.size()) > options_.keyframe_lag && trig <= options_.updates_until) {
          const auto& kf = clones_[clones_.size() - 1 - static_cast<size_t>(options_.keyframe_lag)];
          const auto& cur = clones_.back();
          pending_.push_back({sim_.TimeOf(trig + options_.update_delay), kf.first, cur.first,
                              NoisyRelativePose(kf.second, cur.second, rel_cov_, rng_)});
        }
        while (static_cast<int>(clones_.size()) > options_.keyframe_lag + 1) clones_.pop_front();
      }
    }
  }
  const auto t0 = Clock::now();
  filter_->Propagate(s);
  const auto t1 = Clock::now();
  if (timed) timed(0, Seconds(t0, t1));
  truth_in_frame_ = ToFrame(sim_.truth());

  while (!pending_.empty() && pending_.front().arrival <= s.time) {
    const PendingMeasurement m = pending_.front();
    pending_.pop_front();
    const auto a = Clock::now();
    filter_->ApplyRelativePose(m.keyframe, m.current, m.T, rel_cov_);
    const auto b = Clock::now();
    if (timed) timed(1, Seconds(a, b));
  }
  if (options_.wheel_rate > 0.0 && t >= static_cast<double>(next_wheel_) / options_.wheel_rate) {
    ++next_wheel_;
    const TrajectoryPoint& w = sim_.truth();
    const Eigen::Vector3d v_body = w.q.conjugate() * w.v;
    std::normal_distribution<double> n(0.0, 1.0);
    BodyVelocity bv;
    bv.time = s.time;
    bv.v_xy = v_body.head<2>() + 0.02 * DrawVector2(n, rng_);
    bv.covariance = Eigen::Matrix2d::Identity() * 0.02 * 0.02;
    const auto a = Clock::now();
    filter_->ApplyWheelOdometry(bv);
    const auto b = Clock::now();
    if (timed) timed(2, Seconds(a, b));
  }
  if (options_.switch_period > 0.0 && t >= static_cast<double>(next_switch_) * options_.switch_period) {
    ++next_switch_;
    const auto a = Clock::now();
    const FrameSwitchResult r = filter_->RequestFrameSwitch();
    const auto b = Clock::now();
    if (timed) timed(3, Seconds(a, b));
    if (r.result == FilterResult::kApplied) {
      // The true new frame: the true body position and yaw now (body = IMU here).
      const TrajectoryPoint& w = sim_.truth();
      const Eigen::Matrix3d R = w.q.toRotationMatrix();
      const double yaw = std::atan2(R(1, 0), R(0, 0));
      T_world_frame_ = Eigen::Isometry3d::Identity();
      T_world_frame_.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
      T_world_frame_.translation() = w.p;
      truth_in_frame_ = ToFrame(w);
    }
  }
  return true;
}

}  // namespace cairn::testing
