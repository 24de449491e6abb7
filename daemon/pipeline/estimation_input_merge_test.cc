#include "daemon/pipeline/estimation_input_merge.h"

#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

struct Queues {
  SpscQueue<Queued<ImuSample>> imu{16};
  SpscQueue<Queued<WheelOdometrySample>> wheel{16};
  SpscQueue<Queued<TriggerEvent>> trigger{16};
  SpscQueue<Queued<Timestamp>> clone{16};
  SpscQueue<Queued<VoResult>> vo{16};
  SpscQueue<Queued<FilterSwitchRequest>> frame_switch{16};
  EstimationInputMerge merge{imu, wheel, trigger, clone, vo, frame_switch};

  // Pops what the merge chose, as the estimation thread does.
  EstimationInput PopNext() {
    const std::optional<EstimationInput> next = merge.Next();
    EXPECT_TRUE(next.has_value());
    switch (*next) {
      case EstimationInput::kImu:
        imu.PopFront();
        break;
      case EstimationInput::kWheel:
        wheel.PopFront();
        break;
      case EstimationInput::kTrigger:
        trigger.PopFront();
        break;
      case EstimationInput::kClone:
        clone.PopFront();
        break;
      case EstimationInput::kVoResult:
        vo.PopFront();
        break;
      case EstimationInput::kFrameSwitch:
        frame_switch.PopFront();
        break;
    }
    return *next;
  }
};

Timestamp Ms(int64_t ms) { return Timestamp::FromNanoseconds(ms * 1'000'000); }

TEST(EstimationInputMergeTest, EmptyQueuesGiveNothing) {
  Queues q;
  EXPECT_TRUE(q.merge.empty());
  EXPECT_FALSE(q.merge.Next().has_value());
}

TEST(EstimationInputMergeTest, InputsComeOutInTimestampOrder) {
  Queues q;
  ImuSample imu;
  imu.time = Ms(30);
  ASSERT_TRUE(q.imu.TryPush({0, imu}));
  imu.time = Ms(10);
  ASSERT_TRUE(q.imu.TryPush({0, imu}));  // a queue's own order is kept, even out of time order
  WheelOdometrySample wheel;
  wheel.time = Ms(20);
  ASSERT_TRUE(q.wheel.TryPush({0, wheel}));
  ASSERT_TRUE(q.clone.TryPush({0, Ms(5)}));
  VoResult vo;
  vo.time = Ms(25);
  ASSERT_TRUE(q.vo.TryPush({0, vo}));
  EXPECT_FALSE(q.merge.empty());
  const std::vector<EstimationInput> expected = {EstimationInput::kClone, EstimationInput::kWheel,
                                                 EstimationInput::kVoResult, EstimationInput::kImu,
                                                 EstimationInput::kImu};
  for (EstimationInput e : expected) EXPECT_EQ(q.PopNext(), e);
  EXPECT_TRUE(q.merge.empty());
}

// Equal times: sensor data first, then what the pipeline derived from it, in the enum's order.
TEST(EstimationInputMergeTest, TiesGoToTheInputListedFirst) {
  Queues q;
  const Timestamp t = Ms(100);
  ASSERT_TRUE(q.frame_switch.TryPush({0, FilterSwitchRequest{t, FrameSwitchReason::kDistance}}));
  VoResult vo;
  vo.time = t;
  ASSERT_TRUE(q.vo.TryPush({0, vo}));
  ASSERT_TRUE(q.clone.TryPush({0, t}));
  ASSERT_TRUE(q.trigger.TryPush({0, TriggerEvent{t, 1}}));
  WheelOdometrySample wheel;
  wheel.time = t;
  ASSERT_TRUE(q.wheel.TryPush({0, wheel}));
  ImuSample imu;
  imu.time = t;
  ASSERT_TRUE(q.imu.TryPush({0, imu}));
  for (EstimationInput e :
       {EstimationInput::kImu, EstimationInput::kWheel, EstimationInput::kTrigger, EstimationInput::kClone,
        EstimationInput::kVoResult, EstimationInput::kFrameSwitch}) {
    EXPECT_EQ(q.PopNext(), e);
  }
  EXPECT_FALSE(q.merge.Next().has_value());
}

}  // namespace
}  // namespace cairn
