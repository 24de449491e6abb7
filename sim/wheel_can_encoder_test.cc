#include "sim/wheel_can_encoder.h"

#include <cmath>

#include <gtest/gtest.h>

#include "drivers/can_wheel_decoder.h"
#include "sim/candump_format.h"
#include "sim/rover_can_layout.h"
#include "sim/sim_robot.h"

namespace cairn::sim {
namespace {

// The rover profile's CAN layout, frames through candump text, back through the decoder that the
// SocketCAN driver uses: the decoded wheel states are the simulated ones up to quantization.
TEST(WheelCanEncoderTest, CandumpFramesDecodeToTheSimulatedWheelStates) {
  const CanWheelOptions layout = RoverCanLayout();
  WorldOptions w;
  w.size = 30.0;
  w.resolution = 0.2;
  w.lander.clear();
  const Terrain terrain = Terrain::Generate(w);
  const SimRobot rover = MakeRover(terrain, "rover", 0, 3, 5.0, 0.1, 0.16);
  WheelCanEncoder encoder(layout, rover.wheels[0].z(), 42);
  const WheelCanStream stream = encoder.Generate(rover.trajectory, Timestamp::FromSeconds(100.0), 5.0, 100.0);
  ASSERT_EQ(stream.reported.size(), 501u);

  CanWheelDecoder decoder(layout);
  std::vector<WheelOdometrySample> decoded;
  for (const TimedCanFrame& f : stream.frames) {
    auto rec = ParseCandumpLine(FormatCandumpLine(f.time, "can0", f.frame));
    ASSERT_TRUE(rec.ok()) << rec.status().ToString();
    WheelOdometrySample s;
    const auto result = decoder.Feed(rec->frame, rec->time, &s);
    ASSERT_NE(result, CanWheelDecoder::Result::kMalformed);
    if (result == CanWheelDecoder::Result::kSampleReady) decoded.push_back(s);
  }
  ASSERT_EQ(decoded.size(), stream.reported.size());
  double mean_speed = 0.0;  // once it drives (it stands still for the first 2 s)
  const size_t driving = 250;
  for (size_t k = 0; k < decoded.size(); ++k) {
    EXPECT_EQ(decoded[k].fresh_mask, 0x0F);
    for (size_t i = 0; i < kMaxWheels; ++i) {
      EXPECT_NEAR(decoded[k].wheels[i].speed, stream.reported[k].wheels[i].speed, 0.0005 + 1e-9);
      EXPECT_NEAR(decoded[k].wheels[i].steering_angle, stream.reported[k].wheels[i].steering_angle, 0.00005 + 1e-9);
      if (k >= driving) mean_speed += decoded[k].wheels[i].speed / (4.0 * static_cast<double>(decoded.size() - driving));
    }
  }
  // The rover drives its loop at 0.4 m/s; encoders read a little faster because of slip.
  EXPECT_GT(mean_speed, 0.38);
  EXPECT_LT(mean_speed, 0.48);
}

TEST(WheelCanEncoderTest, WheelSpeedsFollowRigidBodyKinematicsWithoutNoise) {
  CanWheelOptions layout;
  layout.speed_noise = 0.0;
  const std::vector<double> pos[4] = {{0.35, 0.33}, {0.35, -0.33}, {-0.35, 0.33}, {-0.35, -0.33}};
  WheelCanOptions* w[4] = {&layout.front_left, &layout.front_right, &layout.rear_left, &layout.rear_right};
  for (int i = 0; i < 4; ++i) {
    w[i]->position = pos[i];
    w[i]->speed.id = 0x101 + i;
    w[i]->speed.scale = 0.001;
    w[i]->steering.id = 0x101 + i;
    w[i]->steering.start_byte = 2;
    w[i]->steering.scale = 0.0001;
  }
  // Turning left on flat ground: outer (right) wheels are faster, front wheels steer left.
  std::vector<Eigen::Vector3d> p, e;
  for (int i = 0; i < 10; ++i) {
    const double th = 0.1 * i;
    p.emplace_back(3 * std::sin(th), 3 - 3 * std::cos(th), 0.3);
    e.emplace_back(th, 0.0, 0.0);
  }
  const BSplineTrajectory tr(0.5, p, e);
  const WheelCanStream s = WheelCanEncoder(layout, -0.3, 1).Generate(tr, Timestamp::FromSeconds(1), 1.0, 10);
  const WheelOdometrySample& m = s.reported[5];
  EXPECT_GT(m.wheels[1].speed, m.wheels[0].speed);
  EXPECT_GT(m.wheels[0].steering_angle, 0.05);
  EXPECT_LT(m.wheels[2].steering_angle, -0.05);
}

}  // namespace
}  // namespace cairn::sim
