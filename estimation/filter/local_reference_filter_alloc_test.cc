// Proves that the filter never allocates after construction (the binary counts allocations).

#include <array>
#include <cstdlib>

#include <gtest/gtest.h>

#include "estimation/filter/local_reference_filter.h"
#include "estimation/testing/filter_test_util.h"
#include "tests/support/counting_allocator.h"

namespace cairn {
namespace {

TEST(LocalReferenceFilterAllocationTest, HookCountsAllocations) {
  testing::CountingAllocator::Arm();
  // Through a volatile pointer: a new and delete pair the compiler sees whole may be left out.
  int* volatile p = new int(3);
  const long counted = testing::CountingAllocator::Disarm();
  delete p;
  EXPECT_EQ(counted, 1);
}

TEST(LocalReferenceFilterAllocationTest, NoAllocationAfterConstruction) {
  ImuSimulatorOptions so;
  so.noise = testing::TestNoise();
  so.seed = 3;
  ImuSimulator sim(so);
  FilterOptions o;
  o.wheel_enabled = true;
  o.nonholonomic = true;
  auto filter = std::make_unique<LocalReferenceFilter>(o, testing::TestCalibration());
  std::mt19937_64 rng(9);
  testing::StartFromTruth(sim, *filter, rng);

  struct Pending {
    CloneId kf = kNoClone, cur = kNoClone;
    Eigen::Isometry3d T;
    Timestamp arrival;
  };
  std::array<Pending, 16> pending{};  // fixed ring of in-flight relative poses
  std::array<std::pair<CloneId, TrajectoryPoint>, 8> clones{};
  int pending_head = 0, pending_tail = 0, clone_count = 0;
  Matrix6d cov = Matrix6d::Identity() * 1e-4;
  cov.bottomRightCorner<3, 3>() *= 0.1;

  long allocations = 0;
  int switches = 0, updates = 0, replays_before = 0;
  for (int i = 1; i < 1600; ++i) {
    const ImuSample s = sim.Next();
    const double t = (s.time - sim.TimeOf(0.0)).seconds();
    testing::CountingAllocator::Arm();
    if (i % 10 == 0) {  // camera trigger slightly before this sample
      const double trig = t - 0.0013;
      const CloneRequest c = filter->Clone(sim.TimeOf(trig));
      clones[static_cast<size_t>(clone_count % 8)] = {c.id, sim.Truth(trig)};
      if (clone_count >= 4) {
        const auto& kf = clones[static_cast<size_t>((clone_count - 4) % 8)];
        pending[static_cast<size_t>(pending_tail++ % 16)] = {
            kf.first, c.id, testing::NoisyRelativePose(kf.second, sim.Truth(trig), cov, rng),
            sim.TimeOf(trig + 0.28)};
      }
      ++clone_count;
    }
    filter->Propagate(s);
    while (pending_head < pending_tail && pending[static_cast<size_t>(pending_head % 16)].arrival <= s.time) {
      const Pending& m = pending[static_cast<size_t>(pending_head++ % 16)];
      updates += filter->ApplyRelativePose(m.kf, m.cur, m.T, cov) == FilterResult::kApplied;
    }
    if (i % 8 == 0) {
      const TrajectoryPoint& w = sim.truth();
      BodyVelocity bv;
      bv.time = s.time;
      bv.v_xy = (w.q.conjugate() * w.v).head<2>();
      bv.covariance = Eigen::Matrix2d::Identity() * 0.05 * 0.05;
      filter->ApplyWheelOdometry(bv);
    }
    if (i % 300 == 0) {
      switches += filter->RequestFrameSwitch().result == FilterResult::kApplied;
      filter->ReleaseClone(clones[static_cast<size_t>((clone_count + 3) % 8)].first);
    }
    PoseSample ps;
    filter->PoseAt(s.time - Duration::Milliseconds(100), &ps);
    const FilterOutput out = filter->Output();
    // Bad input takes the rejection paths.
    ImuSample bad = s;
    filter->Propagate(bad);  // duplicate
    bad.gyro.x() = std::nan("");
    filter->Propagate(bad);
    allocations += testing::CountingAllocator::Disarm();
    ASSERT_TRUE(out.initialized);
  }
  EXPECT_EQ(allocations, 0);
  EXPECT_EQ(switches, 5);
  EXPECT_GT(updates, 100);
  EXPECT_GT(static_cast<int>(filter->counters().replays), replays_before + 100);
  EXPECT_GT(filter->counters().updates_applied, 250u);  // relative poses and wheel velocities
}

}  // namespace
}  // namespace cairn
