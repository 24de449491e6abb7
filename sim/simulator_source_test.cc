#include "sim/simulator_source.h"

#include <chrono>
#include <thread>

#include <gtest/gtest.h>

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
