#pragma once
// One simulated robot as a live sensor source inside cairnd: IMU samples, rendered stereo pairs,
// wheel odometry decoded from its simulated CAN frames (through the same CanWheelDecoder the
// SocketCAN driver uses) and, when enabled, GNSS fixes (at their publication time, a latency after
// their measurement) are published in timestamp order, IMU first and GNSS last on ties, paced in
// real time, scaled, or as fast as the sink takes them. Images are rendered when they fall due.

#include <atomic>
#include <memory>
#include <thread>
#include <vector>

#include "drivers/replay/replay_clock.h"
#include "drivers/replay/replay_options.h"
#include "hal/sensor_source_interface.h"
#include "sim/gnss_simulator.h"
#include "sim/gnss_simulator_options.h"
#include "sim/mission_simulator.h"

namespace cairn::sim {

class SimulatorSource final : public SensorSourceInterface {
 public:
  // `pacing`/`speed` as for a replay (ReplayOptions' dataset and deterministic are unused). `gnss`:
  // the robot's GNSS receiver (none unless enabled), its errors drawn from `seed`, the mission's.
  SimulatorSource(std::shared_ptr<const MissionSimulator> simulator, size_t robot, ReplayOptions pacing,
                  const GnssSimulatorOptions& gnss = {}, uint64_t seed = 1);
  ~SimulatorSource() override;

  std::string name() const override { return "sim/" + simulator_->robots()[robot_].name; }
  Status Start(SensorSink* sink) override;
  void Stop() override;
  bool finished() const override { return finished_.load(std::memory_order_acquire); }
  // The mission's IMU, CAN and GNSS streams, generated whole at Start(): they grow with the mission's
  // duration, which a robot's drivers never do.
  size_t memory_bytes() const override;

 private:
  void Run(std::stop_token stop);

  std::vector<ImuTruth> imu_;
  WheelCanStream can_;
  std::vector<GnssTruth> gnss_fixes_;

  std::shared_ptr<const MissionSimulator> simulator_;
  size_t robot_;
  GnssSimulatorOptions gnss_;
  uint64_t seed_;
  ReplayClock clock_;
  SensorSink* sink_ = nullptr;
  std::jthread thread_;
  std::atomic<bool> finished_{false};
};

}  // namespace cairn::sim
