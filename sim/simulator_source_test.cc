#include "sim/simulator_source.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <mutex>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "estimation/math/local_tangent_plane.h"
#include "sim/rover_can_layout.h"
#include "tests/support/recording_sink.h"
#include "tests/support/test_data.h"

namespace cairn::sim {
namespace {

std::shared_ptr<const MissionSimulator> ShortMission() {
  WorldOptions w;
  w.size = 30.0;
  w.resolution = 0.2;
  MissionOptions m;
  m.robots = {"rover", "hexacopter"};
  m.duration = 0.5;
  m.image_scale = 0.1;
  m.render_threads = 2;  // as cairnd renders (and so under ThreadSanitizer too)
  m.can = RoverCanLayout();
  auto sim = MissionSimulator::Create(w, m);
  EXPECT_TRUE(sim.ok());
  return std::shared_ptr<const MissionSimulator>(std::move(*sim));
}

TEST(SimulatorSourceTest, PublishesTheRoversStreamsInTimeOrder) {
  auto sim = ShortMission();
  ReplayOptions fast;
  fast.pacing = ReplayPacing::kFastAsPossible;
  SimulatorSource source(sim, 0, fast);
  EXPECT_EQ(source.name(), "sim/rover");
  testing::RecordingSink sink;
  ASSERT_TRUE(source.Start(&sink).ok());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!source.finished() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(source.finished());
  source.Stop();
  source.Stop();  // idempotent
  std::lock_guard lock(sink.mutex);
  EXPECT_EQ(sink.imu.size(), 101u);     // 200 Hz
  EXPECT_EQ(sink.stereo.size(), 6u);    // 10 Hz
  EXPECT_EQ(sink.wheel.size(), 51u);    // 100 Hz CAN cycles, decoded
  EXPECT_TRUE(sink.faults.empty());
  // The whole mission's streams stay held (the daemon reports them apart from its own memory).
  EXPECT_GE(source.memory_bytes(), 101 * sizeof(ImuTruth) + 51 * sizeof(WheelOdometrySample));
  const auto truth = sim->ImuStream(0);
  for (size_t i = 0; i < sink.imu.size(); ++i) {
    EXPECT_EQ(sink.imu[i].time, truth[i].sample.time);
    EXPECT_EQ(sink.imu[i].accel, truth[i].sample.accel);
  }
  const auto wheels = sim->WheelStream(0);
  for (size_t i = 0; i < sink.wheel.size(); ++i) {
    EXPECT_NEAR(sink.wheel[i].wheels[1].speed, wheels.reported[i].wheels[1].speed, 0.0005 + 1e-9);
  }
  for (size_t i = 0; i < sink.stereo.size(); ++i) {
    const StereoFrame& f = sink.stereo[i];
    EXPECT_EQ(f.frame_counter, i);
    EXPECT_EQ(f.left.width, sim->robots()[0].stereo.left.intrinsics.width);
    EXPECT_FALSE(f.right.empty());
    // Hardware-synchronized: every frame time is also an IMU sample time.
    EXPECT_EQ((f.time - sink.imu.front().time).nanoseconds() % 5000000, 0);
  }
}

// Keeps the order in which IMU samples and GNSS fixes arrive.
class SourceOrderSink final : public SensorSink {
 public:
  struct Event {
    bool gnss = false;
    Timestamp time;
  };
  void OnImu(const ImuSample& s) override { Add({false, s.time}); }
  void OnStereo(const StereoFrame&) override {}
  void OnWheelOdometry(const WheelOdometrySample&) override {}
  void OnTrigger(const TriggerEvent&) override {}
  void OnGnss(const GnssFix& g) override {
    std::lock_guard lock(mutex);
    fixes.push_back(g);
    events.push_back({true, g.time});
  }
  void OnDeviceFault(const DeviceFault&) override {}

  std::mutex mutex;
  std::vector<Event> events;
  std::vector<GnssFix> fixes;

 private:
  void Add(const Event& e) {
    std::lock_guard lock(mutex);
    events.push_back(e);
  }
};

// Runs robot 0 of `sim` to its end, as fast as possible, with a GNSS receiver.
void RunWithGnss(const std::shared_ptr<const MissionSimulator>& sim, const GnssSimulatorOptions& gnss,
                 uint64_t seed, SourceOrderSink* sink) {
  ReplayOptions fast;
  fast.pacing = ReplayPacing::kFastAsPossible;
  SimulatorSource source(sim, 0, fast, gnss, seed);
  ASSERT_TRUE(source.Start(sink).ok());
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!source.finished() && std::chrono::steady_clock::now() < deadline) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(source.finished());
}

TEST(SimulatorSourceTest, PublishesGnssFixesAmongTheImuSamplesAtTheirPublicationTime) {
  auto sim = ShortMission();
  GnssSimulatorOptions gnss;
  gnss.enabled = true;
  gnss.rate_hz = 20.0;
  gnss.latency = 0.0375;
  gnss.sigma_horizontal = 0.5;
  gnss.sigma_vertical = 1.0;
  gnss.bias_sigma = 0.3;
  gnss.outage_rate = 0.0;
  gnss.antenna_z = 1.2;
  SourceOrderSink sink, again, other_seed;
  RunWithGnss(sim, gnss, 7, &sink);
  RunWithGnss(sim, gnss, 7, &again);
  RunWithGnss(sim, gnss, 8, &other_seed);
  std::lock_guard lock(sink.mutex);
  // Measured every 50 ms from 0 to 0.45 s (the fix of 0.5 s would be published after the end).
  ASSERT_EQ(sink.fixes.size(), 10u);
  const Timestamp start = sim->start();
  const Duration latency = Duration::Nanoseconds(37500000);
  for (size_t k = 0; k < sink.fixes.size(); ++k) {
    EXPECT_EQ(sink.fixes[k].time, start + Duration::Milliseconds(50 * static_cast<int64_t>(k)));
    EXPECT_EQ(sink.fixes[k].quality, GnssQuality::kAutonomous);
  }
  // Each fix comes after the IMU samples up to its publication time and before the later ones.
  for (size_t j = 0; j < sink.events.size(); ++j) {
    if (!sink.events[j].gnss) continue;
    const Timestamp published = sink.events[j].time + latency;
    for (size_t i = 0; i < sink.events.size(); ++i) {
      if (sink.events[i].gnss) continue;
      if (i < j) {
        EXPECT_LE(sink.events[i].time, published);
      } else {
        EXPECT_GT(sink.events[i].time, published);
      }
    }
  }
  // The fixes are those GnssSimulator makes for the robot: its antenna, within 5 sigma.
  const auto expected =
      GnssSimulator(gnss, 7, 0).Generate(sim->robots()[0].trajectory, start, sim->duration());
  ASSERT_EQ(expected.size(), sink.fixes.size());
  const LocalTangentPlane plane(
      {gnss.origin_latitude * kDegree, gnss.origin_longitude * kDegree, gnss.origin_height});
  for (size_t k = 0; k < sink.fixes.size(); ++k) {
    const GnssFix& f = sink.fixes[k];
    EXPECT_EQ(f.latitude, expected[k].fix.latitude);
    EXPECT_EQ(f.height, expected[k].fix.height);
    const Eigen::Isometry3d T_world_body =
        sim->robots()[0].trajectory.Evaluate((f.time - start).seconds()).T_world_body;
    const Eigen::Vector3d error =
        plane.ToEnu({f.latitude, f.longitude, f.height}) - T_world_body * Eigen::Vector3d(0, 0, 1.2);
    for (int a = 0; a < 3; ++a) {
      EXPECT_LT(std::abs(error[a]), 5 * std::sqrt(f.covariance(a, a))) << k << " " << a;
    }
  }
  // The same seed gives the same fixes, another seed others.
  std::lock_guard lock_again(again.mutex), lock_other(other_seed.mutex);
  ASSERT_EQ(again.fixes.size(), sink.fixes.size());
  ASSERT_EQ(other_seed.fixes.size(), sink.fixes.size());
  for (size_t k = 0; k < sink.fixes.size(); ++k) {
    EXPECT_EQ(again.fixes[k].latitude, sink.fixes[k].latitude);
    EXPECT_EQ(again.fixes[k].longitude, sink.fixes[k].longitude);
    EXPECT_NE(other_seed.fixes[k].latitude, sink.fixes[k].latitude);
  }
}

TEST(SimulatorSourceTest, GnssOutagesRemoveFixes) {
  auto sim = ShortMission();
  GnssSimulatorOptions gnss;
  gnss.enabled = true;
  gnss.rate_hz = 100.0;
  gnss.latency = 0.0;
  gnss.outage_rate = 1.0;
  gnss.outage_mean_duration = 0.2;
  // Seeds whose outages fall within the short mission (found by GnssSimulator, which the source uses).
  uint64_t seed = 1;
  std::vector<GnssTruth> expected;
  for (; seed < 100; ++seed) {
    expected =
        GnssSimulator(gnss, seed, 0).Generate(sim->robots()[0].trajectory, sim->start(), sim->duration());
    if (expected.size() < 40) break;
  }
  ASSERT_LT(expected.size(), 40u);
  SourceOrderSink sink;
  RunWithGnss(sim, gnss, seed, &sink);
  std::lock_guard lock(sink.mutex);
  ASSERT_EQ(sink.fixes.size(), expected.size());  // of 51 without outages
  EXPECT_GT(sink.fixes.size(), 0u);
  for (size_t k = 0; k < sink.fixes.size(); ++k) EXPECT_EQ(sink.fixes[k].time, expected[k].fix.time);
}

// Through the source, 2000 fixes of a 20 s drive have the configured sigmas (white noise only here:
// the bias decorrelates too slowly for a short mission; GnssSimulatorTest checks it over days).
TEST(SimulatorSourceTest, GnssErrorsHaveTheConfiguredSigmas) {
  WorldOptions w;
  w.size = 30.0;
  w.resolution = 0.2;
  MissionOptions m;
  m.robots = {"rover"};
  m.duration = 20.0;
  m.image_scale = 0.05;
  m.can = RoverCanLayout();
  auto created = MissionSimulator::Create(w, m);
  ASSERT_TRUE(created.ok());
  const std::shared_ptr<const MissionSimulator> sim(std::move(*created));
  GnssSimulatorOptions gnss;
  gnss.enabled = true;
  gnss.rate_hz = 100.0;
  gnss.latency = 0.0;
  gnss.sigma_horizontal = 0.4;
  gnss.sigma_vertical = 0.9;
  gnss.bias_sigma = 0.0;
  gnss.outage_rate = 0.0;
  gnss.antenna_x = -0.3;
  gnss.antenna_z = 1.3;
  SourceOrderSink sink;
  RunWithGnss(sim, gnss, 3, &sink);
  std::lock_guard lock(sink.mutex);
  ASSERT_EQ(sink.fixes.size(), 2001u);  // 100 Hz over 20 s
  const LocalTangentPlane plane(
      {gnss.origin_latitude * kDegree, gnss.origin_longitude * kDegree, gnss.origin_height});
  Eigen::Vector3d sum = Eigen::Vector3d::Zero(), sum2 = Eigen::Vector3d::Zero();
  for (const GnssFix& f : sink.fixes) {
    const Eigen::Isometry3d T_world_body =
        sim->robots()[0].trajectory.Evaluate((f.time - sim->start()).seconds()).T_world_body;
    const Eigen::Vector3d e =
        plane.ToEnu({f.latitude, f.longitude, f.height}) - T_world_body * Eigen::Vector3d(-0.3, 0.0, 1.3);
    sum += e;
    sum2 += e.cwiseProduct(e);
  }
  const double n = static_cast<double>(sink.fixes.size());
  const Eigen::Vector3d mean = sum / n;
  const Eigen::Vector3d sigma = (sum2 / n - mean.cwiseProduct(mean)).cwiseSqrt();
  std::printf("through the source: mean %+.4f %+.4f %+.4f m, sigma %.4f %.4f %.4f m (model 0.4 0.4 0.9)\n",
              mean.x(), mean.y(), mean.z(), sigma.x(), sigma.y(), sigma.z());
  // With 2000 samples a sample sigma is within 1.6 % (1 sigma) of the true one.
  EXPECT_NEAR(sigma.x() / 0.4, 1.0, 0.06);
  EXPECT_NEAR(sigma.y() / 0.4, 1.0, 0.06);
  EXPECT_NEAR(sigma.z() / 0.9, 1.0, 0.06);
  EXPECT_LT(mean.head<2>().norm(), 0.05);
  EXPECT_LT(std::abs(mean.z()), 0.1);
}

// A source without GNSS (the default) publishes no fixes.
TEST(SimulatorSourceTest, NoGnssUnlessEnabled) {
  SourceOrderSink sink;
  RunWithGnss(ShortMission(), GnssSimulatorOptions{}, 1, &sink);
  std::lock_guard lock(sink.mutex);
  EXPECT_TRUE(sink.fixes.empty());
  EXPECT_EQ(sink.events.size(), 101u);
}

TEST(SimulatorSourceTest, StopsPromptlyInRealTime) {
  ReplayOptions realtime;
  realtime.pacing = ReplayPacing::kRealTime;
  SimulatorSource source(ShortMission(), 1, realtime);
  testing::RecordingSink sink;
  ASSERT_TRUE(source.Start(&sink).ok());
  EXPECT_TRUE(sink.WaitFor([&] { return !sink.imu.empty(); }));
  source.Stop();
  EXPECT_FALSE(source.finished());
  std::lock_guard lock(sink.mutex);
  EXPECT_TRUE(sink.wheel.empty());  // a hexacopter has no wheels
}

}  // namespace
}  // namespace cairn::sim
