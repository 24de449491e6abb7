#pragma once
// The estimation thread's inputs merged into one stream in timestamp order: IMU samples, wheel
// odometry, camera triggers, clone requests at exposure times, VO results and frame-switch
// requests, each from its own bounded queue. Equal times go to the input listed first in
// EstimationInput (sensor data before what the pipeline derived from it), so a deterministic
// replay consumes one and the same sequence on every run. Reads the queues' fronts only; the
// caller consumes the chosen one. Consumer side of every queue: one thread.

#include <cstdint>
#include <optional>

#include "common/timestamp.h"
#include "daemon/pipeline/estimation_stage.h"
#include "daemon/pipeline/queued.h"
#include "daemon/pipeline/spsc_queue.h"
#include "estimation/vo/keyframe_visual_odometry.h"
#include "hal/imu_sample.h"
#include "hal/trigger_event.h"
#include "hal/wheel_odometry_sample.h"

namespace cairn {

enum class EstimationInput : uint8_t { kImu, kWheel, kTrigger, kClone, kVoResult, kFrameSwitch };

class EstimationInputMerge {
 public:
  EstimationInputMerge(const SpscQueue<Queued<ImuSample>>& imu,
                       const SpscQueue<Queued<WheelOdometrySample>>& wheel,
                       const SpscQueue<Queued<TriggerEvent>>& trigger,
                       const SpscQueue<Queued<Timestamp>>& clone,
                       const SpscQueue<Queued<VoResult>>& vo_result,
                       const SpscQueue<Queued<FilterSwitchRequest>>& frame_switch)
      : imu_(imu),
        wheel_(wheel),
        trigger_(trigger),
        clone_(clone),
        vo_result_(vo_result),
        frame_switch_(frame_switch) {}

  // The input whose front is earliest; nullopt when every queue is empty.
  std::optional<EstimationInput> Next() const;
  bool empty() const;

 private:
  const SpscQueue<Queued<ImuSample>>& imu_;
  const SpscQueue<Queued<WheelOdometrySample>>& wheel_;
  const SpscQueue<Queued<TriggerEvent>>& trigger_;
  const SpscQueue<Queued<Timestamp>>& clone_;
  const SpscQueue<Queued<VoResult>>& vo_result_;
  const SpscQueue<Queued<FilterSwitchRequest>>& frame_switch_;
};

}  // namespace cairn
