// The daemon's estimation chain on synthetic data (a rendered room seen by a camera at rest,
// IMU at rest): blank, over-exposed and dropped frames are reported as odometry failures while
// the filter keeps producing its estimate at every frame from the IMU; and, in live mode (nobody
// waits for anybody), dense stereo and mapping on their own thread beside it.

#include <chrono>
#include <cmath>
#include <thread>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/pipeline/pipeline.h"
#include "estimation/testing/vo_test_scene.h"

namespace cairn {
namespace {

Image MakeImage(const std::vector<uint8_t>& pixels, int w, int h) {
  std::shared_ptr<uint8_t[]> buf(new uint8_t[pixels.size()]);
  std::copy(pixels.begin(), pixels.end(), buf.get());
  Image im;
  im.data = buf;
  im.width = w;
  im.height = h;
  im.stride = w;
  return im;
}

EstimationSetup RoomSetup(const RectifiedStereoCamera& cam) {
  EstimationSetup setup;
  setup.stereo.left.intrinsics = PinholeRadTan{cam.width, cam.height, cam.f, cam.f, cam.cx, cam.cy, 0, 0, 0, 0};
  setup.stereo.right = setup.stereo.left;
  setup.stereo.right.T_body_cam.translation().x() = cam.baseline;  // already rectified: no remap
  setup.imu.gyro_noise_density = 1.7e-4;
  setup.imu.accel_noise_density = 2e-3;
  setup.imu.gyro_random_walk = 2e-5;
  setup.imu.accel_random_walk = 3e-3;
  setup.filter.init_duration = 0.5;
  return setup;
}

TEST(VoPipelineTest, BadAndDroppedFramesAreReportedAndTheFilterKeepsRunning) {
  const RectifiedStereoCamera cam = testing::VoTestScene::EurocLikeCamera();
  const EstimationSetup setup = RoomSetup(cam);
  ExecutorsOptions ex;
  QueueOptions queues;
  Pipeline p(ex, queues, PipelineRates{200.0, 20.0, 0.0}, /*deterministic=*/true);
  ASSERT_TRUE(p.EnableEstimation(setup).ok());
  p.Start();

  const testing::VoTestScene scene(cam, 5);
  const testing::RenderedPair view = scene.Render(Eigen::Isometry3d::Identity());
  const Image left = MakeImage(view.left, cam.width, cam.height), right = MakeImage(view.right, cam.width, cam.height);
  const std::vector<uint8_t> black(view.left.size(), 0), white(view.left.size(), 255);
  const Image blank = MakeImage(black, cam.width, cam.height), over = MakeImage(white, cam.width, cam.height);

  const int64_t t0 = 1'000'000'000;
  uint64_t counter = 0;
  int frames = 0, imu = 0;
  for (int k = 0; k <= 600; ++k) {  // 3 s at 200 Hz
    const Timestamp t = Timestamp::FromNanoseconds(t0 + k * 5'000'000LL);
    ImuSample s;
    s.time = t;
    s.accel = Eigen::Vector3d(0.0, 0.0, 9.81);
    p.OnImu(s);
    ++imu;
    if (k % 10 != 0) continue;  // 20 Hz camera
    const int n = k / 10;
    ++counter;
    if (n == 42) continue;  // the camera numbers this frame, it never arrives
    StereoFrame f;
    f.time = t;
    f.frame_counter = counter;
    f.left = n == 30 ? blank : n == 31 ? over : left;
    f.right = n == 30 ? blank : n == 31 ? over : right;
    p.OnStereo(f);
    ++frames;
  }
  p.StopAndDrain();

  const VoStageReport& vo = *p.vo_report();
  EXPECT_EQ(vo.by_status[static_cast<size_t>(VoStatus::kBadExposure)], 2u);
  EXPECT_EQ(vo.by_status[static_cast<size_t>(VoStatus::kDroppedFrame)], 1u);
  EXPECT_EQ(vo.frames, static_cast<uint64_t>(frames) + 1);
  const EstimationReport e = p.estimation_report();
  EXPECT_TRUE(e.initialized);
  // Every IMU sample after the 0.5 s static initialization is integrated, right to the end.
  EXPECT_EQ(p.imu_stats().count(), static_cast<uint64_t>(imu));
  EXPECT_GE(e.filter.imu_accepted, static_cast<uint64_t>(imu - 105));
  EXPECT_GT(e.vo_updates_applied, 40u);
  // An estimate at every frame once the filter runs, the failed ones included, and the body
  // stays where it is.
  const Trajectory& traj = *p.trajectory();
  ASSERT_GE(traj.poses.size(), 45u);
  bool saw_blank = false;
  for (const StampedPose& pose : traj.poses) {
    EXPECT_LT(pose.T_frame_body.translation().norm(), 0.01);
    saw_blank = saw_blank || pose.time == Timestamp::FromNanoseconds(t0 + 300 * 5'000'000LL);
  }
  EXPECT_TRUE(saw_blank);
}

// Also the graph thread, the tag detector (handed the graph's places by the graph thread) and the
// live stream (its /graph view and the log sink) beside them.
TEST(VoPipelineTest, LiveMappingRunsBesideTheOdometryAndCountsWhatItDrops) {
  const RectifiedStereoCamera cam = testing::VoTestScene::EurocLikeCamera();
  EstimationSetup setup = RoomSetup(cam);
  setup.frame_switch.enabled = false;  // mapping partitions
  MappingSetup mapping;
  mapping.robot = "test";
  mapping.stereo.enabled = true;
  mapping.stereo.every_nth_frame = 5;
  mapping.stereo.sgm.num_disparities = 64;
  mapping.mapping.enabled = true;
  mapping.mapping.write_submaps = false;
  mapping.mapping.write_map = false;
  mapping.mapping.map.depth.max_depth_error = 0.5;  // the room's far wall
  ExecutorsOptions ex;
  QueueOptions queues;
  Pipeline p(ex, queues, PipelineRates{200.0, 20.0, 0.0}, /*deterministic=*/false);
  ASSERT_TRUE(p.EnableEstimation(setup).ok());
  ASSERT_TRUE(p.EnableMapping(mapping).ok());
  GraphStageOptions graph;
  graph.enabled = true;
  graph.pose_every = 2;
  ASSERT_TRUE(p.EnableGraph(graph).ok());
  TagCarrierTable carriers;
  ASSERT_TRUE(carriers.Add(3, "other", false, 0.16, Eigen::Isometry3d::Identity()).ok());
  ASSERT_TRUE(carriers.Add(7, "lander", true, 0.32, Eigen::Isometry3d::Identity()).ok());
  RobotDetectionOptions detection;
  detection.enabled = true;
  detection.error_model = "online";
  ASSERT_TRUE(p.EnableDetection(detection, carriers, "test", "").ok());
  TelemetryStage telemetry(ExecutorOptions{}, 64, /*deterministic=*/false);
  LiveStreamOptions live;
  live.enabled = true;
  live.port = 0;
  ASSERT_TRUE(telemetry.EnableLiveStream("test", live).ok());
  telemetry.Start();
  p.SetTelemetry(&telemetry);
  p.Start();
  const testing::VoTestScene scene(cam, 5);
  const testing::RenderedPair view = scene.Render(Eigen::Isometry3d::Identity());
  const Image left = MakeImage(view.left, cam.width, cam.height), right = MakeImage(view.right, cam.width, cam.height);
  const int64_t t0 = 1'000'000'000;
  const auto dense_taken = [&p] {
    for (const QueueReport& q : p.queue_reports()) {
      if (q.name == "dense") return q.pushed;
    }
    return uint64_t{0};
  };
  // 1 s of IMU first: the filter initializes (0.5 s still window) before the first pair. Then IMU
  // and 20 Hz pairs paced like devices (a full queue drops), until mapping has taken a few pairs
  // however slow this machine is (sanitizers, parallel tests), within 60 s of data.
  uint64_t taken_at_start = 0;
  for (int k = 0; k <= 12000; ++k) {
    const Timestamp t = Timestamp::FromNanoseconds(t0 + k * 5'000'000LL);
    ImuSample s;
    s.time = t;
    s.accel = Eigen::Vector3d(0.0, 0.0, 9.81);
    p.OnImu(s);
    if (k < 200) continue;
    if (k == 200) taken_at_start = dense_taken();
    if (k % 10 == 0) {
      StereoFrame f;
      f.time = t;
      f.frame_counter = static_cast<uint64_t>(k / 10 + 1);
      f.left = left;
      f.right = right;
      p.OnStereo(f);
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    if (k >= 600 && dense_taken() >= taken_at_start + 4) break;
  }
  p.StopAndDrain();
  telemetry.StopAndDrain();
  const MappingStageReport m = p.mapping_report();
  ASSERT_NE(p.graph(), nullptr);
  const GraphStageReport g = p.graph()->report();
  EXPECT_GT(g.estimates, 0u);
  EXPECT_GT(g.robot_poses, 0u);
  ASSERT_NE(p.detection(), nullptr);
  EXPECT_GT(p.detection()->report().predictions, 0u);  // no tag in the room: no carrier placed
  EXPECT_EQ(g.rejected_factors, 0u);
  EXPECT_EQ(g.unplaced, 0u);
  EXPECT_EQ(g.frame_switches, p.estimation_report().frame_switches);
  EXPECT_EQ(m.submaps_placed_by_graph, m.submaps_finished);
  EXPECT_EQ(p.graph()->GlobalTrajectory().poses.size(), g.estimates);
  EXPECT_GT(m.pairs, 0u);
  EXPECT_EQ(m.match_failures, 0u);
  EXPECT_EQ(m.mapping_errors, 0u);
  EXPECT_GT(m.images_mapped, 0u);
  EXPECT_GT(m.mapper.points, 0);
  EXPECT_GE(m.submaps_finished, 1u);  // the open one, finished at the end
  EXPECT_GT(m.map_points, 0u);
  // Every pair that entered the dense queue was matched; what did not fit is counted as dropped.
  bool found = false;
  for (const QueueReport& q : p.queue_reports()) {
    if (q.name != "dense") continue;
    found = true;
    EXPECT_EQ(m.pairs + m.match_failures, q.pushed);
  }
  EXPECT_TRUE(found);
}

}  // namespace
}  // namespace cairn
