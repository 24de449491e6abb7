#include "daemon/run_summary.h"

#include <gtest/gtest.h>

#include "common/json_value.h"

namespace cairn {
namespace {

Pipeline IdlePipeline() {
  QueueOptions queues;
  queues.imu = 8;
  queues.wheel_odometry = 8;
  queues.stereo = 2;
  return Pipeline(ExecutorsOptions{}, queues, PipelineRates{200.0, 20.0, 0.0}, true);
}

TEST(RunSummaryTest, TriggerStampingIsReportedWhenTheCamerasRanOnATrigger) {
  const Pipeline pipeline = IdlePipeline();
  RunInfo run;
  run.robot = "rover";
  run.mode = "live";
  EXPECT_FALSE(JsonValue::Parse(BuildSummaryJson(run, pipeline)).has("trigger_stamping"));

  TriggerFrameStamperCounts counts;
  counts.edges = 120;
  counts.stamped = 117;
  counts.unmatched = 2;
  counts.lonely_edges = 3;
  counts.relearns = 1;
  counts.delay_learned = true;
  counts.delay = 0.0125;
  run.trigger_stamping = counts;
  const JsonValue summary = JsonValue::Parse(BuildSummaryJson(run, pipeline));
  ASSERT_TRUE(summary.has("trigger_stamping"));
  const JsonValue& t = summary["trigger_stamping"];
  EXPECT_EQ(t["edges"].number(), 120);
  EXPECT_EQ(t["stamped_frames"].number(), 117);
  EXPECT_EQ(t["unmatched_frames"].number(), 2);
  EXPECT_EQ(t["edges_without_frame"].number(), 3);
  EXPECT_EQ(t["delay_relearned"].number(), 1);
  EXPECT_TRUE(t["delay_learned"].boolean());
  EXPECT_DOUBLE_EQ(t["delay_s"].number(), 0.0125);

  // No delay is given before one was learned.
  run.trigger_stamping->delay_learned = false;
  EXPECT_FALSE(JsonValue::Parse(BuildSummaryJson(run, pipeline))["trigger_stamping"].has("delay_s"));
}

}  // namespace
}  // namespace cairn
