#include "estimation/filter/local_reference_filter.h"

#include <cmath>
#include <cstdio>

#include <gtest/gtest.h>

#include "estimation/filter/filter_update.h"
#include "estimation/filter/imu_propagator.h"
#include "estimation/testing/filter_scenario.h"
#include "estimation/testing/filter_test_util.h"

namespace cairn {
namespace {

using testing::ChiSquareBand95;
using testing::FilterScenario;
using testing::Nees;
using testing::ScenarioHooks;
using testing::ScenarioOptions;
using testing::StateError;

// Variance of the ZYX yaw of the IMU attitude: dyaw = a^T R dtheta.
double YawVariance(const FilterState& s) {
  const Eigen::Matrix3d R = s.q.toRotationMatrix();
  const double yaw = std::atan2(R(1, 0), R(0, 0));
  const double pitch = std::asin(-R(2, 0));
  const Eigen::RowVector3d y =
      Eigen::RowVector3d(std::tan(pitch) * std::cos(yaw), std::tan(pitch) * std::sin(yaw), 1.0) * R;
  return y * s.P.block<3, 3>(kTheta, kTheta) * y.transpose();
}

// Covariance of the velocity in the IMU frame (frame independent).
Eigen::Matrix3d BodyVelocityCovariance(const FilterState& s) {
  Eigen::Matrix<double, 3, kStateDim> H = Eigen::Matrix<double, 3, kStateDim>::Zero();
  H.block<3, 3>(0, kV) = s.q.toRotationMatrix().transpose();
  H.block<3, 3>(0, kTheta) = so3::Skew(s.q.conjugate() * s.v);
  return H * s.P * H.transpose();
}

// World-frame attitude covariance (left perturbation) of the IMU.
Eigen::Matrix3d WorldAttitudeCovariance(const FilterState& s) {
  const Eigen::Matrix3d R = s.q.toRotationMatrix();
  return R * s.P.block<3, 3>(kTheta, kTheta) * R.transpose();
}

// Average NEES of [p, v, theta] over Monte-Carlo runs at fixed checkpoints.
struct NeesResult {
  std::vector<double> mean_per_checkpoint;
  double overall = 0.0;
};

NeesResult MonteCarloNees(ScenarioOptions scenario, const FilterOptions& options, int runs,
                          double checkpoint_period) {
  const int checkpoints = static_cast<int>(scenario.duration / checkpoint_period);
  NeesResult r;
  r.mean_per_checkpoint.assign(static_cast<size_t>(checkpoints), 0.0);
  for (int run = 0; run < runs; ++run) {
    scenario.seed = 1000 + static_cast<uint64_t>(run);
    FilterScenario sim(scenario, options);
    int next = 1;
    double t0 = -1.0;
    ScenarioHooks hooks;
    hooks.after_sample = [&](const LocalReferenceFilter& f, const TrajectoryPoint& truth) {
      if (t0 < 0.0) t0 = f.state().time.seconds() - truth.t;
      if (next > checkpoints || truth.t < next * checkpoint_period) return;
      const double nees = Nees(f.state(), StateError(f.state(), truth.p, truth.v, truth.q));
      r.mean_per_checkpoint[static_cast<size_t>(next - 1)] += nees / runs;
      ++next;
    };
    sim.Run(hooks);
  }
  for (double m : r.mean_per_checkpoint) r.overall += m / checkpoints;
  return r;
}

void ExpectConsistent(const ScenarioOptions& s, const FilterOptions& o) {
  // Kept small for the sanitizer CI; exact delay handling is tested separately.
  constexpr int kRuns = 16;
  const NeesResult r = MonteCarloNees(s, o, kRuns, 2.0);
  const auto [lo, hi] = ChiSquareBand95(9.0 * kRuns, kRuns);
  for (size_t i = 0; i < r.mean_per_checkpoint.size(); ++i) {
    std::printf("checkpoint %zu: mean NEES %.2f (band %.2f..%.2f)\n", i, r.mean_per_checkpoint[i], lo, hi);
  }
  EXPECT_GT(r.overall, lo);
  EXPECT_LT(r.overall, hi);
  // Individual checkpoints may leave a 95 % band by chance; none may be far outside.
  for (double m : r.mean_per_checkpoint) {
    EXPECT_GT(m, 0.7 * lo);
    EXPECT_LT(m, 1.3 * hi);
  }
}

TEST(LocalReferenceFilterTest, MonteCarloNeesIsConsistentWithDelayedRelativePoses) {
  ScenarioOptions s;
  s.duration = 10.0;
  s.update_delay = 0.1;
  ExpectConsistent(s, FilterOptions{});
}

TEST(LocalReferenceFilterTest, RepeatedFrameSwitchesKeepTheFilterConsistent) {
  ScenarioOptions s;
  s.duration = 10.0;
  s.update_delay = 0.05;
  s.switch_period = 1.7;  // not on a checkpoint: right at a switch P is singular by design
  s.wheel_rate = 10.0;
  FilterOptions o;
  o.wheel_enabled = true;
  ExpectConsistent(s, o);
}

TEST(LocalReferenceFilterTest, YawAndPositionUnobservableRollPitchObservable) {
  ScenarioOptions s;
  s.duration = 30.0;
  s.update_delay = 0.1;
  FilterScenario sim(s, FilterOptions{});
  double yaw_var_5 = 0, yaw_var_end = 0, pos_var_5 = 0, pos_var_end = 0, rp_var_5 = 0, rp_var_end = 0;
  double rp_var_max_late = 0.0;
  ScenarioHooks hooks;
  hooks.after_sample = [&](const LocalReferenceFilter& f, const TrajectoryPoint& truth) {
    const Eigen::Matrix3d A = WorldAttitudeCovariance(f.state());
    const double pos = f.state().P.block<3, 3>(kP, kP).trace();
    if (std::abs(truth.t - 5.0) < 1e-6) {
      yaw_var_5 = A(2, 2);
      pos_var_5 = pos;
      rp_var_5 = A(0, 0) + A(1, 1);
    }
    if (truth.t > 20.0) rp_var_max_late = std::max(rp_var_max_late, A(0, 0) + A(1, 1));
    yaw_var_end = A(2, 2);
    pos_var_end = pos;
    rp_var_end = A(0, 0) + A(1, 1);
  };
  sim.Run(hooks);
  ASSERT_GT(yaw_var_5, 0.0);
  // Unobservable: uncertainty only grows.
  EXPECT_GT(yaw_var_end, 1.5 * yaw_var_5);
  EXPECT_GT(pos_var_end, 2.0 * pos_var_5);
  // Observable: roll and pitch stay bounded well below their initial 0.01 rad sigma.
  EXPECT_LT(rp_var_end, rp_var_5);
  EXPECT_LT(std::sqrt(rp_var_max_late), 0.005);

  // Without any update every direction grows (pure dead reckoning).
  ScenarioOptions none = s;
  none.camera_rate = 0.0;
  none.duration = 10.0;
  FilterScenario dr(none, FilterOptions{});
  double first_pos = -1.0;
  dr.Run({.after_sample = [&](const LocalReferenceFilter& f, const TrajectoryPoint&) {
    if (first_pos < 0) first_pos = f.state().P.block<3, 3>(kP, kP).trace();
  }});
  EXPECT_GT((dr.filter().state().P.block<3, 3>(kP, kP).trace()), 100.0 * first_pos);
}

// Runs the same data with relative poses delivered at once and `delay` later.
void ExpectDelayedEqualsInOrder(double delay, double switch_period) {
  ScenarioOptions s;
  s.duration = 6.0;
  s.updates_until = 5.5;  // the late run has received everything by the end
  s.wheel_rate = 25.0;
  s.switch_period = switch_period;
  FilterOptions o;
  o.wheel_enabled = true;
  ScenarioOptions late = s;
  late.update_delay = delay;
  FilterScenario a(s, o), b(late, o);
  a.Run();
  b.Run();
  const FilterState& x = a.filter().state();
  const FilterState& y = b.filter().state();
  EXPECT_EQ(x.time, y.time);
  EXPECT_LT((x.p - y.p).norm(), 1e-9);
  EXPECT_LT((x.v - y.v).norm(), 1e-9);
  EXPECT_LT(so3::Log(x.q.conjugate() * y.q).norm(), 1e-9);
  EXPECT_LT((x.ba - y.ba).norm(), 1e-9);
  EXPECT_LT((x.bg - y.bg).norm(), 1e-9);
  EXPECT_LT((x.P - y.P).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT((x.phi - y.phi).cwiseAbs().maxCoeff(), 1e-9);
  for (int i = 0; i < kMaxClones; ++i) {
    EXPECT_EQ(x.clones[i].id, y.clones[i].id);
    EXPECT_LT((x.clones[i].p_frame_imu - y.clones[i].p_frame_imu).norm(), 1e-9);
  }
  EXPECT_GT(b.filter().counters().replays, 50u);
  EXPECT_EQ(a.filter().counters().updates_applied, b.filter().counters().updates_applied);
  // The delayed run really differed from in-order processing before the late updates landed.
  EXPECT_GT(b.filter().counters().replayed_imu_samples, 10u * b.filter().counters().replays);
}

TEST(LocalReferenceFilterTest, DelayedRelativePoseEqualsInOrderProcessing) {
  ExpectDelayedEqualsInOrder(0.3, 0.0);
}

TEST(LocalReferenceFilterTest, DelayedUpdatesAroundFrameSwitchesAreDeterministic) {
  // Across a switch a late relative pose is applied at the switch, so runs with different delays
  // differ; the same delay must reproduce the same result and stay finite.
  ScenarioOptions s;
  s.duration = 5.0;
  s.update_delay = 0.3;
  s.switch_period = 1.0;
  FilterScenario a(s, FilterOptions{}), b(s, FilterOptions{});
  a.Run();
  b.Run();
  EXPECT_EQ((a.filter().state().P - b.filter().state().P).cwiseAbs().maxCoeff(), 0.0);
  EXPECT_TRUE(a.filter().state().P.allFinite());
  const FilterCounters& c = a.filter().counters();
  EXPECT_GT(c.updates_direct, 0u);
  EXPECT_GT(c.updates_applied, 3 * c.updates_rejected);
  EXPECT_EQ(c.frame_switches, 5u);
}

// The state after a short run with delayed relative poses and wheel updates: clones, their cross
// blocks deferred or current.
FilterState StateAfterDelayedRun() {
  ScenarioOptions s;
  s.duration = 2.0;
  s.update_delay = 0.25;
  s.wheel_rate = 20.0;
  FilterOptions o;
  o.wheel_enabled = true;
  FilterScenario a(s, o);
  a.Run();
  return a.filter().state();
}

// Replay snapshots keep P packed (its current parts only): restoring must reproduce the saved
// matrix bit for bit, from a deferred and from a complete covariance, into either kind of state.
TEST(LocalReferenceFilterTest, PackedCovarianceRestoresTheMatrixExactly) {
  const FilterState deferred = StateAfterDelayedRun();
  ASSERT_TRUE(deferred.cross_pending);
  // The stale parts of a deferred P are held at zero.
  constexpr int kCloneDims = kStateDim - kCoreDim;
  EXPECT_EQ((deferred.P.topRightCorner<kCoreDim, kCloneDims>().cwiseAbs().maxCoeff()), 0.0);
  for (int j = 1; j < kMaxClones; ++j) {
    EXPECT_EQ(deferred.P.block(kCoreDim, CloneIndex(j), 6 * j, 6).cwiseAbs().maxCoeff(), 0.0) << j;
  }
  FilterState complete_state = deferred;
  MaterializeCovariance(complete_state);
  const FilterState& complete = complete_state;
  ASSERT_FALSE(complete.cross_pending);
  ASSERT_GT((complete.P - deferred.P).cwiseAbs().maxCoeff(), 0.0);

  PackedCovariance packed;
  for (const FilterState* saved : {&deferred, &complete}) {
    PackCovariance(saved->P, packed);
    for (const FilterState* target : {&deferred, &complete}) {
      FilterState t = *target;
      t.P(kCoreDim, kCoreDim) += 1.0;  // something to overwrite
      UnpackCovariance(packed, saved->cross_pending, t);
      EXPECT_TRUE((t.P.array() == saved->P.array()).all())
          << "saved " << saved->cross_pending << " into " << target->cross_pending;
    }
  }
}

// IMU steps reach phi and the current clone cross blocks as one block-structured product at the
// next event: applying each step's product at once must give the same covariance.
TEST(LocalReferenceFilterTest, PendingTransitionProductEqualsStepwiseApplication) {
  FilterState once = StateAfterDelayedRun();
  FlushTransition(once);
  ASSERT_TRUE(once.cross_pending);
  int current = 0, deferred = 0;
  for (int j = 0; j < kMaxClones; ++j) {
    if (once.clones[static_cast<size_t>(j)].id == kNoClone) continue;
    (once.cross_current[static_cast<size_t>(j)] ? current : deferred) += 1;
  }
  ASSERT_GT(current, 0);
  ASSERT_GT(deferred, 0);
  FilterState stepwise = once;
  const ImuPropagator propagator(ImuNoise::FromCalibration(testing::TestCalibration()),
                                   FilterOptions{}.gravity);
  for (int k = 1; k <= 40; ++k) {
    const double u = 0.05 * k;
    const Eigen::Vector3d accel(0.8 * std::sin(u), -0.5 * std::cos(2.0 * u), 9.81 + 0.3 * std::sin(3.0 * u));
    const Eigen::Vector3d gyro(0.4 * std::cos(u), 0.2 * std::sin(2.0 * u), -0.6 * std::sin(u));
    const Timestamp t = once.time + Duration::Milliseconds(5);
    propagator.Propagate(once, t, accel, gyro);
    propagator.Propagate(stepwise, t, accel, gyro);
    FlushTransition(stepwise);
  }
  ASSERT_FALSE(once.pending_transition.identity);
  MaterializeCovariance(once);
  MaterializeCovariance(stepwise);
  EXPECT_LT((once.P - stepwise.P).cwiseAbs().maxCoeff(), 1e-12 * once.P.cwiseAbs().maxCoeff());
}

TEST(LocalReferenceFilterTest, FrameSwitchKeepsPoseAndResetsPositionAndYaw) {
  ScenarioOptions s;
  s.duration = 4.0;
  s.update_delay = 0.1;
  FilterScenario sim(s, FilterOptions{});
  sim.Run();
  LocalReferenceFilter& f = sim.filter();
  const FilterState before = f.state();
  const FilterOutput out_before = f.Output();
  const Eigen::Matrix3d A = WorldAttitudeCovariance(before);
  const FrameSwitchResult r = f.RequestFrameSwitch();
  ASSERT_EQ(r.result, FilterResult::kApplied);
  EXPECT_EQ(r.new_frame_id, r.old_frame_id + 1);
  const FilterOutput out_after = f.Output();
  EXPECT_EQ(out_after.frame_id, r.new_frame_id);

  // The pose expressed in the old frame does not change.
  const Eigen::Isometry3d T_old_body = r.transform.T_old_new * out_after.T_frame_body;
  EXPECT_LT((T_old_body.matrix() - out_before.T_frame_body.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  EXPECT_LT(out_after.T_frame_body.translation().norm(), 1e-12);
  const Eigen::Matrix3d R = out_after.T_frame_body.linear();
  EXPECT_NEAR(std::atan2(R(1, 0), R(0, 0)), 0.0, 1e-12);
  // The new frame is gravity aligned: the transform rotates about z only.
  EXPECT_NEAR(r.transform.T_old_new.linear()(2, 2), 1.0, 1e-12);

  // Position and yaw uncertainty are now zero; roll/pitch, velocity and biases are kept.
  const FilterState& after = f.state();
  EXPECT_LT((after.P.block<3, 3>(kP, kP).cwiseAbs().maxCoeff()), 1e-15);
  EXPECT_LT(YawVariance(after), 1e-15);
  const Eigen::Matrix3d A2 = WorldAttitudeCovariance(after);
  EXPECT_NEAR(A2(0, 0) + A2(1, 1), A(0, 0) + A(1, 1), 0.05 * (A(0, 0) + A(1, 1)));
  EXPECT_LT((BodyVelocityCovariance(after) - BodyVelocityCovariance(before)).cwiseAbs().maxCoeff(),
            1e-12);
  EXPECT_LT(((after.P.block<6, 6>(kBa, kBa) - before.P.block<6, 6>(kBa, kBa)).cwiseAbs().maxCoeff()), 1e-15);
  // The transform carries the old position and yaw uncertainty.
  EXPECT_NEAR((r.transform.covariance.topLeftCorner<3, 3>().trace()), (before.P.block<3, 3>(kP, kP).trace()), 1e-12);
  EXPECT_NEAR(r.transform.covariance(5, 5), YawVariance(before), 1e-9 * YawVariance(before));
  EXPECT_LT((r.transform.covariance.block<2, 2>(3, 3).cwiseAbs().maxCoeff()), 1e-15);

  // Relative poses between clones, and their uncertainty, do not depend on the frame.
  int pairs = 0;
  for (int i = 0; i < kMaxClones; ++i) {
    for (int j = 0; j < kMaxClones; ++j) {
      if (i == j || before.clones[i].id == kNoClone || before.clones[j].id == kNoClone) continue;
      ++pairs;
      RelativePoseMeasurement m;
      m.keyframe_slot = i;
      m.current_slot = j;
      const Matrix6d C0 = RelativePoseCovariance(before, m);
      const Matrix6d C1 = RelativePoseCovariance(after, m);
      EXPECT_LT((C0 - C1).cwiseAbs().maxCoeff(), 1e-9 * C0.cwiseAbs().maxCoeff());
      const CloneSlot &a0 = before.clones[i], &b0 = before.clones[j];
      const CloneSlot &a1 = after.clones[i], &b1 = after.clones[j];
      const Eigen::Vector3d d0 = a0.q_frame_imu.conjugate() * (b0.p_frame_imu - a0.p_frame_imu);
      const Eigen::Vector3d d1 = a1.q_frame_imu.conjugate() * (b1.p_frame_imu - a1.p_frame_imu);
      EXPECT_LT((d0 - d1).norm(), 1e-12);
    }
  }
  EXPECT_GT(pairs, 0);
  // The history keeps poses in the frame they were estimated in.
  PoseSample p;
  ASSERT_TRUE(f.PoseAt(before.time, &p));
  EXPECT_EQ(p.frame_id, r.old_frame_id);
}

TEST(LocalReferenceFilterTest, PoseAtInterpolatesRecentHistory) {
  ScenarioOptions s;
  s.duration = 2.0;
  s.camera_rate = 0.0;
  FilterScenario sim(s, FilterOptions{});
  std::vector<PoseSample> seen;
  sim.Run({.after_sample = [&](const LocalReferenceFilter& f, const TrajectoryPoint&) {
    seen.push_back({f.state().time, f.frame_id(), f.Output().T_frame_body, Matrix6d::Zero()});
  }});
  const LocalReferenceFilter& f = sim.filter();
  const PoseSample& a = seen[seen.size() - 10];
  const PoseSample& b = seen[seen.size() - 9];
  PoseSample got;
  ASSERT_TRUE(f.PoseAt(a.time, &got));
  EXPECT_LT((got.T_frame_body.matrix() - a.T_frame_body.matrix()).cwiseAbs().maxCoeff(), 1e-12);
  const Timestamp mid = a.time + (b.time - a.time) / 2;
  ASSERT_TRUE(f.PoseAt(mid, &got));
  const Eigen::Vector3d expected = 0.5 * (a.T_frame_body.translation() + b.T_frame_body.translation());
  EXPECT_LT((got.T_frame_body.translation() - expected).norm(), 1e-12);
  EXPECT_FALSE(f.PoseAt(f.state().time + Duration::Milliseconds(1), &got));
  EXPECT_FALSE(f.PoseAt(Timestamp::FromSeconds(1.0), &got));
}

TEST(LocalReferenceFilterTest, BadSamplesAreRejectedAndCounted) {
  ScenarioOptions s;
  s.duration = 1.0;
  FilterScenario sim(s, FilterOptions{});
  sim.Run();
  LocalReferenceFilter& f = sim.filter();
  const Timestamp now = f.state().time;
  const Duration dt = Duration::Milliseconds(5);
  ImuSample good;
  good.time = now + dt;
  good.accel = Eigen::Vector3d(0, 0, 9.81);

  ImuSample nan = good;
  nan.gyro.x() = std::nan("");
  EXPECT_EQ(f.Propagate(nan), FilterResult::kRejectedNotFinite);
  ImuSample inf = good;
  inf.accel.z() = std::numeric_limits<double>::infinity();
  EXPECT_EQ(f.Propagate(inf), FilterResult::kRejectedNotFinite);
  ImuSample far = good;
  far.time = now + Duration::Seconds(1e6);
  EXPECT_EQ(f.Propagate(far), FilterResult::kRejectedFarFuture);
  EXPECT_EQ(f.Propagate(good), FilterResult::kApplied);
  EXPECT_EQ(f.Propagate(good), FilterResult::kRejectedDuplicate);
  ImuSample old = good;
  old.time = now - dt;
  EXPECT_EQ(f.Propagate(old), FilterResult::kRejectedOutOfOrder);
  ImuSample next = good;
  next.time = good.time + dt;
  EXPECT_EQ(f.Propagate(next), FilterResult::kApplied);
  EXPECT_EQ(f.state().time, next.time);

  const FilterCounters& c = f.counters();
  EXPECT_EQ(c.imu_not_finite, 2u);
  EXPECT_EQ(c.imu_far_future, 1u);
  EXPECT_EQ(c.imu_duplicate, 1u);
  EXPECT_EQ(c.imu_out_of_order, 1u);
  EXPECT_TRUE(f.state().P.allFinite());

  // Measurements: unknown clones, bad covariances, NaN, far-future and disabled wheel updates.
  const uint64_t rejected = c.updates_rejected;
  EXPECT_EQ(f.ApplyRelativePose(999999, 999998, Eigen::Isometry3d::Identity(), Matrix6d::Identity()),
            FilterResult::kRejectedUnknownClone);
  EXPECT_EQ(f.ApplyRelativePose(1, 2, Eigen::Isometry3d::Identity(), -Matrix6d::Identity()),
            FilterResult::kRejectedBadCovariance);
  Eigen::Isometry3d bad = Eigen::Isometry3d::Identity();
  bad.translation().x() = std::nan("");
  EXPECT_EQ(f.ApplyRelativePose(1, 2, bad, Matrix6d::Identity()), FilterResult::kRejectedNotFinite);
  EXPECT_EQ(f.ApplyPosition(f.state().time + Duration::Seconds(100.0), Eigen::Vector3d::Zero(),
                            Eigen::Matrix3d::Identity()),
            FilterResult::kRejectedFarFuture);
  EXPECT_EQ(f.ApplyPosition(f.state().time - Duration::Seconds(10.0), Eigen::Vector3d::Zero(),
                            Eigen::Matrix3d::Identity()),
            FilterResult::kRejectedTooOld);
  BodyVelocity bv;
  bv.time = f.state().time;
  EXPECT_EQ(f.ApplyWheelOdometry(bv), FilterResult::kRejectedDisabled);
  EXPECT_EQ(c.updates_rejected, rejected + 6);
  EXPECT_EQ(f.Clone(f.state().time - Duration::Seconds(10.0)).result, FilterResult::kRejectedTooOld);
  EXPECT_EQ(f.ReleaseClone(424242), FilterResult::kRejectedUnknownClone);

  // A real gap: a consistent run of samples after a long silence is accepted after
  // imu_resync_samples, and the filter continues.
  const FilterOptions o;
  ImuSample g = next;
  g.time = next.time + Duration::Seconds(5.0);
  FilterResult last = FilterResult::kRejectedFarFuture;
  int tries = 0;
  while (last != FilterResult::kApplied && tries < 1000) {
    last = f.Propagate(g);
    g.time += dt;
    ++tries;
  }
  EXPECT_EQ(tries, o.imu_resync_samples);
  EXPECT_EQ(c.imu_resyncs, 1u);
  EXPECT_EQ(f.Propagate(g), FilterResult::kApplied);
  EXPECT_TRUE(f.state().P.allFinite());
}

TEST(LocalReferenceFilterTest, StaticInitializationAndMotionPolicy) {
  ImuSimulatorOptions so;
  so.noise = testing::TestNoise();
  so.motion_scale = 0.0;
  so.initial_gyro_bias = Eigen::Vector3d(0.004, -0.002, 0.003);
  so.seed = 5;
  ImuSimulator sim(so);
  FilterOptions o;
  LocalReferenceFilter f(o, testing::TestCalibration());
  // A bump while the window fills restarts it.
  int n = 0;
  FilterResult r = FilterResult::kInitializing;
  while (r == FilterResult::kInitializing && n < 2000) {
    ImuSample s = sim.Next();
    if (n == 100) s.gyro.x() += 0.5;
    r = f.Propagate(s);
    ++n;
  }
  ASSERT_EQ(r, FilterResult::kApplied);
  // The window restarts after the 0.1 s block that holds the bump and then needs 1 s of data.
  EXPECT_GE(n, 101 + 200);
  EXPECT_LE(n, 101 + 200 + 22);
  EXPECT_EQ(f.Output().initialized, true);
  EXPECT_EQ(f.Clone(f.state().time).result, FilterResult::kApplied);
  const FilterOutput out = f.Output();
  EXPECT_TRUE(out.initialized);
  EXPECT_LT((out.gyro_bias - so.initial_gyro_bias).norm(), 1e-3);
  // Roll and pitch from gravity: compare the estimated gravity direction in the IMU frame.
  const Eigen::Vector3d up_true = sim.truth().q.conjugate() * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d up_est = f.state().q.conjugate() * Eigen::Vector3d::UnitZ();
  EXPECT_LT(std::acos(std::min(1.0, up_true.dot(up_est))), 1e-3);
  // Before initialization nothing else is accepted.
  LocalReferenceFilter g(o, testing::TestCalibration());
  EXPECT_EQ(g.Clone(Timestamp::FromSeconds(1.0)).result, FilterResult::kNotInitialized);
  EXPECT_EQ(g.RequestFrameSwitch().result, FilterResult::kNotInitialized);
  EXPECT_FALSE(g.Output().initialized);
}

// A rover rolling at constant speed on flat ground gives a quiet IMU: its wheels must hold the
// initialization back until it stops.
TEST(LocalReferenceFilterTest, TurningWheelsHoldStaticInitializationBack) {
  ImuSimulatorOptions so;
  so.noise = testing::TestNoise();
  so.motion_scale = 0.0;
  so.seed = 6;
  ImuSimulator sim(so);
  FilterOptions o;
  o.wheel_enabled = true;
  LocalReferenceFilter f(o, testing::TestCalibration());
  BodyVelocity rolling;
  rolling.v_xy = Eigen::Vector2d(0.4, 0.0);
  rolling.covariance = Eigen::Matrix2d::Identity() * 1e-4;
  BodyVelocity stopped = rolling;
  stopped.v_xy.setZero();
  int n = 0;
  FilterResult r = FilterResult::kInitializing;
  // 3 s of quiet IMU data with the wheels turning (wheel samples at 20 Hz), then stopped.
  while (r == FilterResult::kInitializing && n < 2000) {
    ImuSample s = sim.Next();
    if (n % 10 == 0) {
      BodyVelocity& v = n < 600 ? rolling : stopped;
      v.time = s.time;
      EXPECT_EQ(f.ApplyWheelOdometry(v), FilterResult::kNotInitialized);
    }
    r = f.Propagate(s);
    ++n;
  }
  ASSERT_EQ(r, FilterResult::kApplied);
  // The window starts with the first block after the wheels stop and needs 1 s of data.
  EXPECT_GE(n, 590 + 200);
  EXPECT_LE(n, 600 + 200 + 22);
  // Without wheels turning the same data initializes after the first second.
  LocalReferenceFilter g(o, testing::TestCalibration());
  ImuSimulator again(so);
  int m = 0;
  r = FilterResult::kInitializing;
  while (r == FilterResult::kInitializing && m < 2000) {
    ImuSample s = again.Next();
    if (m % 10 == 0) {
      stopped.time = s.time;
      g.ApplyWheelOdometry(stopped);
    }
    r = g.Propagate(s);
    ++m;
  }
  EXPECT_LE(m, 200 + 22);
}

TEST(LocalReferenceFilterTest, ClonesAreBoundedAndReleasedClonesMarginalized) {
  ScenarioOptions s;
  s.duration = 3.0;
  FilterOptions o;
  o.max_clones = 5;
  FilterScenario sim(s, o);
  sim.Run();
  LocalReferenceFilter& f = sim.filter();
  EXPECT_EQ(f.active_clones(), 5);
  EXPECT_GT(f.counters().clones_marginalized, 40u);
  CloneId newest = kNoClone;
  for (const CloneSlot& c : f.state().clones) newest = std::max(newest, c.id);
  EXPECT_EQ(f.ReleaseClone(newest), FilterResult::kApplied);
  EXPECT_EQ(f.active_clones(), 4);
  for (int i = 0; i < kMaxClones; ++i) {
    if (f.state().clones[i].id != kNoClone) continue;
    EXPECT_EQ((f.state().P.middleRows<6>(CloneIndex(i)).cwiseAbs().maxCoeff()), 0.0);
  }
  // Clone 1 was marginalized long ago: nothing can refer to it any more.
  EXPECT_EQ(f.ApplyRelativePose(1, newest, Eigen::Isometry3d::Identity(), Matrix6d::Identity()),
            FilterResult::kRejectedUnknownClone);
  EXPECT_EQ(f.active_clones(), 4);
}

}  // namespace
}  // namespace cairn
