// The stamper between a triggered camera and the daemon's sink: frames in order, a missed edge, a
// dropped frame, an edge later than its frame, jittered delays with losses, no trigger at all,
// camera clocks offset from the trigger's, and edges and frames from two threads.

#include "drivers/trigger_frame_stamper.h"

#include <atomic>
#include <chrono>
#include <random>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/recording_sink.h"

namespace cairn {
namespace {

constexpr Duration kPeriod = Duration::Milliseconds(100);  // 10 Hz, the rover's cameras
constexpr Duration kExposure = Duration::Milliseconds(4);
// The camera's own time of a frame is this much after its edge (its trigger delay, half the
// exposure and the error of its clock mapping).
constexpr Duration kOwnDelay = Duration::Milliseconds(14);
const Timestamp kStart = Timestamp::FromSeconds(1000.0);

Timestamp EdgeTime(int k) { return kStart + kPeriod * k; }

TriggerEvent Edge(int k) { return TriggerEvent{EdgeTime(k), static_cast<uint64_t>(k)}; }

StereoFrame Frame(int k, Duration own_delay = kOwnDelay, uint64_t counter = 0) {
  StereoFrame f;
  f.time = EdgeTime(k) + own_delay;
  f.exposure = kExposure;
  f.frame_counter = counter != 0 ? counter : static_cast<uint64_t>(k) + 1;
  return f;
}

class TriggerFrameStamperTest : public ::testing::Test {
 protected:
  TriggerFrameStamperTest() {
    options_.latency = 0.0005;
    options_.max_delay = 0.04;
    options_.tolerance = 0.005;
    options_.edge_wait = 0.002;
  }
  // Where a frame stamped at edge k must be: the edge, the trigger delay, half the exposure.
  Timestamp Stamped(int k) const { return EdgeTime(k) + Duration::Seconds(options_.latency) + kExposure / 2; }
  std::unique_ptr<TriggerFrameStamper> Make() {
    return std::make_unique<TriggerFrameStamper>(options_, &sink_, "trigger");
  }

  TriggerFrameStamperOptions options_;
  testing::RecordingSink sink_;
};

TEST_F(TriggerFrameStamperTest, FramesInOrderTakeTheirEdgesTimes) {
  auto stamper = Make();
  for (int k = 0; k < 20; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k));
  }
  ASSERT_EQ(sink_.stereo.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, Stamped(k)) << "frame " << k;
    EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].frame_counter, static_cast<uint64_t>(k) + 1);
  }
  EXPECT_EQ(sink_.triggers.size(), 20u);  // the edges go on too
  EXPECT_TRUE(sink_.faults.empty());
  const TriggerFrameStamperCounts c = stamper->counts();
  EXPECT_EQ(c.stamped, 20u);
  EXPECT_EQ(c.unmatched, 0u);
  EXPECT_EQ(c.lonely_edges, 0u);
  EXPECT_TRUE(c.delay_learned);
  EXPECT_NEAR(c.delay, (kOwnDelay - kExposure / 2).seconds(), 1e-9);
}

TEST_F(TriggerFrameStamperTest, AMissedEdgeCostsOnlyItsFrame) {
  // With a known rate the trigger's sequence skips the lost edge; without one it does not. The
  // frames after the loss must find their own edges either way.
  for (const bool sequence_skips : {true, false}) {
    SCOPED_TRACE(sequence_skips ? "sequence skips the lost edge" : "sequence does not skip");
    sink_.stereo.clear();
    sink_.faults.clear();
    auto stamper = Make();
    for (int k = 0; k < 12; ++k) {
      if (k != 5) {
        TriggerEvent e = Edge(k);
        if (!sequence_skips && k > 5) --e.sequence;
        stamper->OnTrigger(e);
      }
      stamper->OnStereo(Frame(k));
    }
    ASSERT_EQ(sink_.stereo.size(), 12u);
    for (int k = 0; k < 12; ++k) {
      const Timestamp want = k == 5 ? Frame(5).time : Stamped(k);
      EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, want) << "frame " << k;
    }
    const TriggerFrameStamperCounts c = stamper->counts();
    EXPECT_EQ(c.stamped, 11u);
    EXPECT_EQ(c.unmatched, 1u);
    ASSERT_EQ(sink_.faults.size(), 1u);
    EXPECT_EQ(sink_.faults[0].kind, DeviceFaultKind::kOther);
    EXPECT_EQ(sink_.faults[0].device, "trigger");
    EXPECT_NE(sink_.faults[0].detail.find("1 frames passed on with their own time"), std::string::npos)
        << sink_.faults[0].detail;
  }
}

TEST_F(TriggerFrameStamperTest, ADroppedFrameCostsOnlyItsEdge) {
  // A window wider than a period holds the dropped frame's edge too: the learned delay (and, with
  // counters, the count) must pass it over. Counters of 0 model a camera that reports none.
  options_.max_delay = 0.15;
  for (const bool counters : {true, false}) {
    SCOPED_TRACE(counters ? "with frame counters" : "without frame counters");
    sink_.stereo.clear();
    auto stamper = Make();
    for (int k = 0; k < 12; ++k) {
      stamper->OnTrigger(Edge(k));
      StereoFrame f = Frame(k);
      if (!counters) f.frame_counter = 0;
      if (k != 5 && k != 6) stamper->OnStereo(f);  // two in a row lost
    }
    ASSERT_EQ(sink_.stereo.size(), 10u);
    size_t i = 0;
    for (int k = 0; k < 12; ++k) {
      if (k == 5 || k == 6) continue;
      EXPECT_EQ(sink_.stereo[i++].time, Stamped(k)) << "frame " << k;
    }
    const TriggerFrameStamperCounts c = stamper->counts();
    EXPECT_EQ(c.stamped, 10u);
    EXPECT_EQ(c.lonely_edges, 2u);
    EXPECT_TRUE(sink_.faults.empty());
  }
}

TEST_F(TriggerFrameStamperTest, TheFrameCounterDecidesBetweenEdgesEquallyNearTheDelay) {
  // A tolerance of more than half a period (a misconfiguration the count survives): after a
  // dropped frame, the next frame's time lies just between its own edge and the unclaimed one.
  options_.max_delay = 0.2;
  options_.tolerance = 0.06;
  auto stamper = Make();
  const Duration own_delay = Duration::Milliseconds(52);  // learned: 50 ms, less half the exposure
  for (int k = 0; k < 5; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k, own_delay));
  }
  stamper->OnTrigger(Edge(5));  // frame 5 is lost
  stamper->OnTrigger(Edge(6));
  stamper->OnStereo(Frame(6, Duration::Milliseconds(2)));  // 50 ms from both edges' expected times
  ASSERT_EQ(sink_.stereo.size(), 6u);
  EXPECT_EQ(sink_.stereo[5].time, Stamped(6));
  EXPECT_EQ(stamper->counts().lonely_edges, 1u);
}

TEST_F(TriggerFrameStamperTest, AnEdgeLaterThanItsFrameIsAwaitedBriefly) {
  options_.edge_wait = 1.0;  // generous: the sanitizers slow the other thread down
  auto stamper = Make();
  for (int k = 0; k < 5; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k));
  }
  // The trigger's thread runs behind: edge 5 comes 20 ms after its frame.
  std::thread late([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    stamper->OnTrigger(Edge(5));
  });
  const auto before = std::chrono::steady_clock::now();
  stamper->OnStereo(Frame(5));
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  late.join();
  ASSERT_EQ(sink_.stereo.size(), 6u);
  EXPECT_EQ(sink_.stereo[5].time, Stamped(5));
  EXPECT_GE(waited, 0.015);
  EXPECT_LT(waited, 0.9);  // woken by the edge, not by the end of the wait
  EXPECT_EQ(stamper->counts().unmatched, 0u);
}

TEST_F(TriggerFrameStamperTest, AnEdgeLaterThanTheWaitIsGivenUp) {
  options_.edge_wait = 0.005;
  auto stamper = Make();
  for (int k = 0; k < 5; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k));
  }
  const auto before = std::chrono::steady_clock::now();
  stamper->OnStereo(Frame(5));  // edge 5 comes only after the frame gave up
  const double waited = std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  stamper->OnTrigger(Edge(5));
  stamper->OnTrigger(Edge(6));
  stamper->OnStereo(Frame(6));
  ASSERT_EQ(sink_.stereo.size(), 7u);
  EXPECT_EQ(sink_.stereo[5].time, Frame(5).time);  // its own
  EXPECT_EQ(sink_.stereo[6].time, Stamped(6));     // not edge 5's
  EXPECT_GE(waited, 0.004);
  const TriggerFrameStamperCounts c = stamper->counts();
  EXPECT_EQ(c.unmatched, 1u);
  EXPECT_EQ(c.lonely_edges, 1u);  // edge 5, passed over by frame 6
}

TEST_F(TriggerFrameStamperTest, JitteredDelaysWithLostEdgesAndFrames) {
  options_.max_delay = 0.15;  // wider than a period: every choice goes through the learned delay
  options_.edge_wait = 0.0005;
  auto stamper = Make();
  std::mt19937 random(7);
  std::uniform_int_distribution<int64_t> period_jitter(-1'000'000, 1'000'000), delay_jitter(-2'000'000, 2'000'000);
  std::bernoulli_distribution lose(0.05);
  std::vector<Timestamp> want;
  int lost_edges = 0, lost_frames = 0;
  Timestamp edge = kStart;
  for (int k = 0; k < 300; ++k) {
    edge = edge + kPeriod + Duration::Nanoseconds(period_jitter(random));
    const bool edge_lost = k > 0 && lose(random);
    const bool frame_lost = !edge_lost && lose(random);
    if (!edge_lost) stamper->OnTrigger(TriggerEvent{edge, static_cast<uint64_t>(k)});
    StereoFrame f;
    f.time = edge + kOwnDelay + Duration::Nanoseconds(delay_jitter(random));
    f.exposure = kExposure;
    f.frame_counter = static_cast<uint64_t>(k) + 1;
    lost_edges += edge_lost;
    lost_frames += frame_lost;
    if (frame_lost) continue;
    want.push_back(edge_lost ? f.time : edge + Duration::Seconds(options_.latency) + kExposure / 2);
    stamper->OnStereo(f);
  }
  ASSERT_GT(lost_edges, 5);
  ASSERT_GT(lost_frames, 5);
  ASSERT_EQ(sink_.stereo.size(), want.size());
  for (size_t i = 0; i < want.size(); ++i) EXPECT_EQ(sink_.stereo[i].time, want[i]) << "frame " << i;
  const TriggerFrameStamperCounts c = stamper->counts();
  EXPECT_EQ(c.unmatched, static_cast<uint64_t>(lost_edges));
  EXPECT_EQ(c.stamped, want.size() - static_cast<size_t>(lost_edges));
  EXPECT_NEAR(c.delay, (kOwnDelay - kExposure / 2).seconds(), 0.002);
  EXPECT_EQ(c.relearns, 0u);
}

TEST_F(TriggerFrameStamperTest, FramesWithoutAnyTriggerKeepTheirTimesAndAreReportedOnceASecond) {
  options_.edge_wait = 0.05;  // must not be waited: no trigger is running
  auto stamper = Make();
  const auto before = std::chrono::steady_clock::now();
  for (int k = 0; k < 30; ++k) stamper->OnStereo(Frame(k));
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  ASSERT_EQ(sink_.stereo.size(), 30u);
  for (int k = 0; k < 30; ++k) EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, Frame(k).time);
  EXPECT_LT(took, 0.5);  // 30 waits would take 1.5 s
  // Frame times 0.014 s, 1.014 s, 2.014 s after the start: one report a second, with the count.
  ASSERT_EQ(sink_.faults.size(), 3u);
  EXPECT_NE(sink_.faults[0].detail.find("1 frames"), std::string::npos) << sink_.faults[0].detail;
  EXPECT_NE(sink_.faults[0].detail.find("no edge received yet"), std::string::npos) << sink_.faults[0].detail;
  EXPECT_NE(sink_.faults[1].detail.find("10 frames"), std::string::npos) << sink_.faults[1].detail;
  EXPECT_NE(sink_.faults[2].detail.find("10 frames"), std::string::npos) << sink_.faults[2].detail;
  EXPECT_EQ(stamper->counts().unmatched, 30u);
}

TEST_F(TriggerFrameStamperTest, ACameraClockOffsetWithinTheWindowIsLearned) {
  // The camera's clock mapping puts its frames 22 ms later than the trigger delay alone would:
  // the stamp comes from the edge and does not carry that offset.
  auto stamper = Make();
  const Duration offset = Duration::Milliseconds(22);
  for (int k = 0; k < 10; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k, kOwnDelay + offset));
  }
  ASSERT_EQ(sink_.stereo.size(), 10u);
  for (int k = 0; k < 10; ++k) EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, Stamped(k));
  EXPECT_NEAR(stamper->counts().delay, (kOwnDelay + offset - kExposure / 2).seconds(), 1e-9);
}

TEST_F(TriggerFrameStamperTest, ACameraOnAnotherClockIsNotStampedAndDoesNotWait) {
  options_.edge_wait = 0.05;
  auto stamper = Make();
  const auto before = std::chrono::steady_clock::now();
  for (int k = 0; k < 20; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k, Duration::Seconds(-3.0)));  // 3 s earlier than its edge
  }
  const double took = std::chrono::duration<double>(std::chrono::steady_clock::now() - before).count();
  ASSERT_EQ(sink_.stereo.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, Frame(k, Duration::Seconds(-3.0)).time);
  }
  EXPECT_LT(took, 0.5);
  EXPECT_EQ(stamper->counts().unmatched, 20u);
  ASSERT_EQ(sink_.faults.size(), 2u);  // frame times 0 s and 1.0 s after the first
  EXPECT_NE(sink_.faults[0].detail.find("newest edge's: -3.0"), std::string::npos) << sink_.faults[0].detail;
}

TEST_F(TriggerFrameStamperTest, AStepInTheCameraClockIsLearnedAgain) {
  // The camera reconnects and its clock mapping restarts 16 ms later: still in the window, beyond
  // the tolerance. Two frames go unstamped, the third relearns.
  auto stamper = Make();
  for (int k = 0; k < 20; ++k) {
    stamper->OnTrigger(Edge(k));
    stamper->OnStereo(Frame(k, k < 10 ? kOwnDelay : kOwnDelay + Duration::Milliseconds(16)));
  }
  ASSERT_EQ(sink_.stereo.size(), 20u);
  for (int k = 0; k < 20; ++k) {
    const bool unstamped = k == 10 || k == 11;
    const Timestamp want = unstamped ? Frame(k, kOwnDelay + Duration::Milliseconds(16)).time : Stamped(k);
    EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, want) << "frame " << k;
  }
  const TriggerFrameStamperCounts c = stamper->counts();
  EXPECT_EQ(c.relearns, 1u);
  EXPECT_EQ(c.unmatched, 2u);
  EXPECT_NEAR(c.delay, (kOwnDelay + Duration::Milliseconds(16) - kExposure / 2).seconds(), 1e-9);
}

TEST_F(TriggerFrameStamperTest, BeforeTheDelayIsKnownTheLatestEdgeInTheWindowIsTaken) {
  options_.max_delay = 0.25;  // two edges fit the first frame
  auto stamper = Make();
  stamper->OnTrigger(Edge(0));
  stamper->OnTrigger(Edge(1));
  stamper->OnStereo(Frame(1));
  stamper->OnTrigger(Edge(2));
  stamper->OnStereo(Frame(2));  // edge 0, never claimed, is still in the window
  ASSERT_EQ(sink_.stereo.size(), 2u);
  EXPECT_EQ(sink_.stereo[0].time, Stamped(1));
  EXPECT_EQ(sink_.stereo[1].time, Stamped(2));
  EXPECT_EQ(stamper->counts().lonely_edges, 1u);
}

TEST_F(TriggerFrameStamperTest, OtherMessagesPassThroughUnchanged) {
  auto stamper = Make();
  ImuSample imu;
  imu.time = Timestamp::FromSeconds(3.0);
  imu.gyro.x() = 0.25;
  stamper->OnImu(imu);
  WheelOdometrySample wheel;
  wheel.time = Timestamp::FromSeconds(4.0);
  stamper->OnWheelOdometry(wheel);
  stamper->OnDeviceFault(DeviceFault{Timestamp::FromSeconds(5.0), "cam", DeviceFaultKind::kTimeout, "quiet"});
  ASSERT_EQ(sink_.imu.size(), 1u);
  EXPECT_EQ(sink_.imu[0].time, imu.time);
  EXPECT_EQ(sink_.imu[0].gyro.x(), 0.25);
  ASSERT_EQ(sink_.wheel.size(), 1u);
  EXPECT_EQ(sink_.wheel[0].time, wheel.time);
  ASSERT_EQ(sink_.faults.size(), 1u);
  EXPECT_EQ(sink_.faults[0].device, "cam");
  EXPECT_EQ(sink_.faults[0].kind, DeviceFaultKind::kTimeout);
}

TEST_F(TriggerFrameStamperTest, EdgesAndFramesFromTwoThreads) {
  options_.edge_wait = 2.0;  // a frame ahead of its edge always gets it (the sanitizers are slow)
  auto stamper = Make();
  constexpr int kFrames = 400;
  std::atomic<int> edges_sent{0}, frames_sent{0};
  // Either side runs up to three frames ahead of the other: frames ahead wait for their edges
  // (within the active window), edges ahead wait in the ring.
  std::thread trigger([&] {
    for (int k = 0; k < kFrames; ++k) {
      while (frames_sent.load() < k - 3) std::this_thread::yield();
      stamper->OnTrigger(Edge(k));
      edges_sent.store(k + 1);
    }
  });
  for (int k = 0; k < kFrames; ++k) {
    while (edges_sent.load() < std::max(1, k - 3)) std::this_thread::yield();
    stamper->OnStereo(Frame(k));
    frames_sent.store(k + 1);
  }
  trigger.join();
  std::lock_guard lock(sink_.mutex);
  ASSERT_EQ(sink_.stereo.size(), static_cast<size_t>(kFrames));
  for (int k = 0; k < kFrames; ++k) EXPECT_EQ(sink_.stereo[static_cast<size_t>(k)].time, Stamped(k)) << "frame " << k;
  EXPECT_EQ(sink_.triggers.size(), static_cast<size_t>(kFrames));
  EXPECT_EQ(stamper->counts().unmatched, 0u);
}

}  // namespace
}  // namespace cairn
