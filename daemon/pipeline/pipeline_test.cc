#include "daemon/pipeline/pipeline.h"

#include <thread>

#include <gtest/gtest.h>

namespace cairn {
namespace {

ExecutorsOptions NormalExecutors() {
  ExecutorsOptions e;  // defaults: no realtime, so tests never depend on privileges
  return e;
}

QueueOptions SmallQueues() {
  QueueOptions q;
  q.imu = 8;
  q.wheel_odometry = 8;
  q.stereo = 2;
  return q;
}

StereoFrame Frame(int64_t ms, uint64_t counter) {
  StereoFrame f;
  f.time = Timestamp::FromNanoseconds(ms * 1000000);
  f.frame_counter = counter;
  auto buf = std::shared_ptr<uint8_t[]>(new uint8_t[16]());
  f.left = Image{buf, 4, 4, 4, PixelFormat::kGray8};
  f.right = f.left;
  return f;
}

TEST(PipelineTest, DeterministicModeConsumesEverySampleWithoutDrops) {
  Pipeline p(NormalExecutors(), SmallQueues(), PipelineRates{200.0, 20.0, 0.0}, true);
  p.Start();
  // Far more samples than the queues hold: the publisher must wait, never drop.
  for (int i = 0; i < 2000; ++i) {
    ImuSample s;
    s.time = Timestamp::FromNanoseconds(int64_t{5000000} * i);
    p.OnImu(s);
    if (i % 10 == 0) p.OnStereo(Frame(5 * i, static_cast<uint64_t>(i / 10)));
    // Each call returns only once its stage has consumed the sample.
    EXPECT_EQ(p.consumed_imu(), static_cast<uint64_t>(i + 1));
  }
  p.StopAndDrain();
  EXPECT_EQ(p.imu_stats().count(), 2000u);
  EXPECT_EQ(p.stereo_stats().count(), 200u);
  EXPECT_EQ(p.imu_stats().gaps(), 0u);
  EXPECT_EQ(p.total_dropped(), 0u);
  EXPECT_EQ(p.stereo_report().frame_counter_gaps, 0u);
  EXPECT_EQ(p.stereo_report().width, 4);
}

TEST(PipelineTest, LivePublishersNeverBlockAndDropsAreCounted) {
  Pipeline p(NormalExecutors(), SmallQueues(), PipelineRates{}, false);
  p.Start();
  constexpr int kFrames = 5000;
  for (int i = 0; i < kFrames; ++i) p.OnStereo(Frame(i, static_cast<uint64_t>(i)));
  p.StopAndDrain();
  const auto queues = p.queue_reports();
  const auto& stereo = queues.back();
  ASSERT_EQ(stereo.name, "stereo");
  EXPECT_EQ(stereo.pushed + stereo.dropped, static_cast<uint64_t>(kFrames));
  EXPECT_EQ(p.stereo_stats().count(), stereo.pushed);  // everything accepted was drained
  // Frames lost in the queue show up as frame-counter gaps downstream.
  // Frame i carries counter i and time i ms; the first frame always fits the empty queue.
  const uint64_t last_counter = static_cast<uint64_t>(p.stereo_stats().last().nanoseconds() / 1000000);
  EXPECT_EQ(p.stereo_report().frame_counter_gaps, last_counter + 1 - p.stereo_stats().count());
}

TEST(PipelineTest, FaultsFromSeveralThreadsAreAllCounted) {
  Pipeline p(NormalExecutors(), SmallQueues(), PipelineRates{}, false);
  p.Start();
  std::vector<std::thread> threads;
  for (int t = 0; t < 4; ++t) {
    threads.emplace_back([&p, t] {
      for (int i = 0; i < 50; ++i) {
        p.OnDeviceFault(DeviceFault{Timestamp(), "dev" + std::to_string(t),
                                    DeviceFaultKind::kCorruptSample, "bad frame"});
      }
    });
  }
  for (auto& th : threads) th.join();
  p.StopAndDrain();
  const FaultReport r = p.fault_report();
  EXPECT_EQ(r.total, 200u);
  EXPECT_EQ(r.counts.at("dev2").at("corrupt_sample"), 50u);
  EXPECT_EQ(r.first_messages.size(), 20u);
}

}  // namespace
}  // namespace cairn
