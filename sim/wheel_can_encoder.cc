#include "sim/wheel_can_encoder.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "drivers/can_wheel_decoder.h"
#include "sim/sim_random.h"

namespace cairn::sim {

WheelCanEncoder::WheelCanEncoder(const CanWheelOptions& layout, double contact_height, uint64_t seed)
    : layout_(layout), contact_height_(contact_height), seed_(seed) {}

WheelCanStream WheelCanEncoder::Generate(const BSplineTrajectory& trajectory, Timestamp start,
                                         double duration, double rate_hz) const {
  const std::array<const WheelCanOptions*, kMaxWheels> wheels = {
      &layout_.front_left, &layout_.front_right, &layout_.rear_left, &layout_.rear_right};
  SimRandom rng(seed_);
  std::array<double, kMaxWheels> slip{};
  const int64_t period_ns = std::llround(1e9 / rate_hz);
  const int64_t count = static_cast<int64_t>(std::floor(duration * rate_hz + 1e-9)) + 1;
  const double dt = 1.0 / rate_hz;
  WheelCanStream out;
  for (int64_t k = 0; k < count; ++k) {
    const Timestamp time = start + Duration::Nanoseconds(k * period_ns);
    const TrajectoryState st = trajectory.Evaluate(static_cast<double>(k * period_ns) * 1e-9);
    const Eigen::Vector3d v_body = st.T_world_body.linear().transpose() * st.velocity;
    WheelOdometrySample s;
    s.time = time;
    s.wheel_count = kMaxWheels;
    s.fresh_mask = (1u << kMaxWheels) - 1;
    for (size_t w = 0; w < kMaxWheels; ++w) {
      const Eigen::Vector3d p(wheels[w]->position[0], wheels[w]->position[1], contact_height_);
      const Eigen::Vector3d vc = v_body + st.omega_body.cross(p);
      double angle = std::atan2(vc.y(), vc.x()), speed = std::hypot(vc.x(), vc.y());
      if (angle > std::numbers::pi / 2) { angle -= std::numbers::pi; speed = -speed; }
      if (angle < -std::numbers::pi / 2) { angle += std::numbers::pi; speed = -speed; }
      // Slip: a slowly wandering fraction (0-15 %) by which the wheel outruns the ground.
      slip[w] = std::clamp(slip[w] + 0.01 * std::sqrt(dt) * rng.Normal() + 0.002 * dt, 0.0, 0.15);
      s.wheels[w].speed = speed * (1.0 + slip[w]) + layout_.speed_noise * rng.Normal();
      s.wheels[w].steering_angle = wheels[w]->steered ? angle + 0.002 * rng.Normal() : 0.0;
    }
    out.reported.push_back(s);
    // One frame per distinct identifier, in the order the layout names them, then the sync frame.
    std::vector<can_frame> frames;
    auto frame_for = [&](const CanSignalOptions& sig) -> can_frame& {
      const canid_t id = static_cast<canid_t>(sig.id) | (sig.extended_id ? CAN_EFF_FLAG : 0u);
      for (can_frame& f : frames) {
        if (f.can_id == id) return f;
      }
      frames.push_back(can_frame{});
      frames.back().can_id = id;
      return frames.back();
    };
    for (size_t w = 0; w < kMaxWheels; ++w) {
      EncodeCanSignal(wheels[w]->speed, s.wheels[w].speed, &frame_for(wheels[w]->speed));
      if (wheels[w]->steered) {
        EncodeCanSignal(wheels[w]->steering, s.wheels[w].steering_angle, &frame_for(wheels[w]->steering));
      }
    }
    if (layout_.sync_id >= 0) {
      const canid_t sync = static_cast<canid_t>(layout_.sync_id) | (layout_.sync_id > 0x7FF ? CAN_EFF_FLAG : 0u);
      bool present = false;
      for (const can_frame& f : frames) present = present || (f.can_id & CAN_EFF_MASK) == (sync & CAN_EFF_MASK);
      if (!present) {
        frames.push_back(can_frame{});
        frames.back().can_id = sync;
      } else {
        // The sync frame carries signals: move it last so that it closes the cycle.
        std::stable_partition(frames.begin(), frames.end(), [&](const can_frame& f) {
          return (f.can_id & CAN_EFF_MASK) != (sync & CAN_EFF_MASK);
        });
      }
    }
    // Frames of one cycle 100 us apart, as a controller sends them back to back.
    for (size_t i = 0; i < frames.size(); ++i) {
      out.frames.push_back({time + Duration::Microseconds(100 * static_cast<int64_t>(i)), frames[i]});
    }
  }
  return out;
}

}  // namespace cairn::sim
