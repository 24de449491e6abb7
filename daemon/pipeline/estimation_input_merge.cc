#include "daemon/pipeline/estimation_input_merge.h"

namespace cairn {
namespace {

// Keeps `best` unless `queue`'s front is strictly earlier, so ties stay with the earlier input.
template <class T, class TimeOf>
void Consider(const SpscQueue<Queued<T>>& queue, EstimationInput input, TimeOf time_of,
              std::optional<EstimationInput>* best, Timestamp* best_time) {
  const Queued<T>* front = queue.Front();
  if (front == nullptr) return;
  const Timestamp t = time_of(front->value);
  if (!best->has_value() || t < *best_time) {
    *best = input;
    *best_time = t;
  }
}

}  // namespace

std::optional<EstimationInput> EstimationInputMerge::Next() const {
  std::optional<EstimationInput> best;
  Timestamp best_time = Timestamp::Max();
  const auto sample_time = [](const auto& v) { return v.time; };
  Consider(imu_, EstimationInput::kImu, sample_time, &best, &best_time);
  Consider(wheel_, EstimationInput::kWheel, sample_time, &best, &best_time);
  Consider(trigger_, EstimationInput::kTrigger, sample_time, &best, &best_time);
  Consider(
      clone_, EstimationInput::kClone, [](Timestamp t) { return t; }, &best, &best_time);
  Consider(vo_result_, EstimationInput::kVoResult, sample_time, &best, &best_time);
  Consider(frame_switch_, EstimationInput::kFrameSwitch, sample_time, &best, &best_time);
  return best;
}

bool EstimationInputMerge::empty() const {
  return imu_.empty() && wheel_.empty() && trigger_.empty() && clone_.empty() && vo_result_.empty() &&
         frame_switch_.empty();
}

}  // namespace cairn
