// cairnd with `source: sim`: the rover of a simulated two-robot mission, end to end through the
// daemon as a user runs it (`cairnd --config configs/rover.yaml --sim`), and the errors a wrong
// simulation setup gives before anything runs.

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "estimation/eval/trajectory.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;
using testing::RunProcess;

std::string Cairnd() { return testing::BinaryDir() + "/daemon/cairnd"; }
std::string Config(const std::string& robot) { return testing::SourceDir() + "/configs/" + robot + ".yaml"; }

// Small images and a short mission keep the test fast (and affordable under the sanitizers).
std::vector<std::string> SimArgs(const std::string& robot, const std::string& out) {
  return {Cairnd(), "--config", Config(robot), "--sim", "--out", out,
          "--set", "sim.duration=2", "--set", "sim.image_scale=0.25",
          "--set", "replay.pacing=fast", "--set", "replay.deterministic=true",
          "--set", "live.enabled=false", "--set", "recording.enabled=false"};
}

TEST(CairndSimTest, RoverPublishesEveryStreamAndWritesGroundTruth) {
  const testing::ScopedTempDir temp("cairnd_sim");
  const std::string out = temp.path();
  const auto r = RunProcess(SimArgs("rover", out));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(out + "/summary.json");
  EXPECT_EQ(s["mode"].string(), "sim");
  EXPECT_EQ(s["stop_reason"].string(), "end_of_data");
  // 2 s at 200 Hz IMU, 10 Hz cameras and 100 Hz wheel cycles, both ends included.
  EXPECT_EQ(s["streams"]["imu"]["count"].number(), 401);
  EXPECT_EQ(s["streams"]["stereo"]["count"].number(), 21);
  EXPECT_GE(s["streams"]["wheel_odometry"]["count"].number(), 190);
  EXPECT_EQ(s["streams"]["imu"]["gaps"].number(), 0);
  EXPECT_EQ(s["stereo"]["width"].number(), 256);   // 1024 * 0.25
  EXPECT_EQ(s["stereo"]["height"].number(), 127);  // 508 * 0.25
  EXPECT_EQ(s["faults"]["total"].number(), 0);
  auto truth = TrajectoryIo::Read(out + "/ground_truth.tum", TrajectoryFormat::kTum);
  ASSERT_TRUE(truth.ok()) << truth.status().ToString();
  EXPECT_EQ(truth->poses.size(), 401u);
}

// Deployed from the lander, the rover sights it while it initializes: in a live run (paced in
// real time, so that the graph keeps up) the graph then hands the detector where it places the
// rover (and the lander) for every image; a deterministic replay, where that would depend on
// thread timing, does without.
TEST(CairndSimTest, TheGraphPlacesTheCarriersForTheDetectorInLiveRunsOnly) {
  const testing::ScopedTempDir temp("cairnd_sim_predictions");
  const std::string out = temp.path();
  auto live = SimArgs("rover", out + "/live");
  *std::find(live.begin(), live.end(), "sim.duration=2") = "sim.duration=3";
  *std::find(live.begin(), live.end(), "sim.image_scale=0.25") = "sim.image_scale=0.5";  // the tag's cells
  *std::find(live.begin(), live.end(), "replay.pacing=fast") = "replay.pacing=realtime";
  *std::find(live.begin(), live.end(), "replay.deterministic=true") = "replay.deterministic=false";
  live.insert(live.end(), {"--set", "sim.deploy_from_lander=true"});
  const auto r = RunProcess(live);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue d = JsonValue::ParseFile(out + "/live/summary.json")["detection"];
  EXPECT_GT(d["graph_landmark_observations"].number(), 0);
  EXPECT_GT(d["predictions"].number(), 0);
  // The graph places the rover from its second second on: every later image would get them.
  const auto replay = RunProcess(SimArgs("rover", out + "/replay"));
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const JsonValue e = JsonValue::ParseFile(out + "/replay/summary.json")["detection"];
  EXPECT_GT(e["images"].number(), 15);
  EXPECT_EQ(e["predictions"].number(), 0);
}

TEST(CairndSimTest, HexacopterHasNoWheels) {
  const testing::ScopedTempDir temp("cairnd_sim_hexa");
  const std::string out = temp.path();
  const auto r = RunProcess(SimArgs("hexacopter", out));
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(out + "/summary.json");
  EXPECT_EQ(s["streams"]["imu"]["count"].number(), 801);  // 400 Hz
  EXPECT_EQ(s["streams"]["wheel_odometry"]["count"].number(), 0);
}

TEST(CairndSimTest, WrongSetupsAreRefusedNamingTheKey) {
  const testing::ScopedTempDir temp("cairnd_sim_bad");
  const std::string out = temp.path();
  auto args = SimArgs("rover", out + "/a");
  args.insert(args.end(), {"--set", "sim.robots=hexacopter"});
  auto r = RunProcess(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("robot.name 'rover' is not one of sim.robots"), std::string::npos) << r.output;
  EXPECT_FALSE(fs::exists(out + "/a/summary.json"));

  args = SimArgs("rover", out + "/b");
  args.insert(args.end(), {"--set", "sim.world=/nonexistent/world.yaml"});
  r = RunProcess(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("sim.world"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("/nonexistent/world.yaml"), std::string::npos) << r.output;

  args = SimArgs("rover", out + "/c");
  args.insert(args.end(), {"--set", "sim.robots=rover,submarine"});
  r = RunProcess(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("submarine"), std::string::npos) << r.output;

  // Region scans between whole-frame scans that do not fall on them; an error table of another
  // camera.
  args = SimArgs("rover", out + "/d");
  args.insert(args.end(), {"--set", "detection.roi_every_nth_frame=3"});
  r = RunProcess(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("detection.roi_every_nth_frame (3) must divide detection.every_nth_frame (2)"),
            std::string::npos)
      << r.output;
  args = SimArgs("rover", out + "/e");
  args.insert(args.end(), {"--set", "detection.error_table=detection/hexacopter.lut"});
  r = RunProcess(args);
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.output.find("hexacopter.lut was built for a 666 px wide camera"), std::string::npos) << r.output;

  r = RunProcess({Cairnd(), "--config", Config("rover"), "--sim", "--replay", "/tmp"});
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.output.find("exclude each other"), std::string::npos) << r.output;
}

// Trajectory exports in every format parse back to the same poses, for the filter's chained
// trajectory and the SLAM graph's global one; a format nobody knows is refused at start-up.
TEST(CairndSimTest, TrajectoriesInEveryFormatReadBack) {
  const testing::ScopedTempDir temp("cairnd_sim_formats");
  const std::string out = temp.path();
  auto args = SimArgs("rover", out);
  args.insert(args.end(), {"--set", "sim.duration=4", "--set", "sim.image_scale=0.5", "--set", "mapping.enabled=false",
                           "--set", "stereo.enabled=false", "--set", "output.trajectory_formats=tum, euroc,kitti"});
  const auto r = RunProcess(args);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  for (const std::string stem : {"trajectory", "global_trajectory"}) {
    auto tum = TrajectoryIo::Read(out + "/" + stem + ".tum", TrajectoryFormat::kTum);
    auto csv = TrajectoryIo::Read(out + "/" + stem + ".csv", TrajectoryFormat::kEurocCsv);
    auto kitti = TrajectoryIo::Read(out + "/" + stem + ".kitti", TrajectoryFormat::kKitti, out + "/" + stem + "_times.txt");
    ASSERT_TRUE(tum.ok() && csv.ok() && kitti.ok()) << stem;
    ASSERT_GT(tum->poses.size(), 5u) << stem;
    ASSERT_EQ(csv->poses.size(), tum->poses.size()) << stem;
    ASSERT_EQ(kitti->poses.size(), tum->poses.size()) << stem;
    for (size_t i = 0; i < tum->poses.size(); ++i) {
      EXPECT_EQ(csv->poses[i].time, tum->poses[i].time);
      EXPECT_LT(std::abs((kitti->poses[i].time - tum->poses[i].time).seconds()), 1e-6);
      EXPECT_LT((csv->poses[i].T_frame_body.matrix() - tum->poses[i].T_frame_body.matrix()).norm(), 1e-6) << i;
      EXPECT_LT((kitti->poses[i].T_frame_body.matrix() - tum->poses[i].T_frame_body.matrix()).norm(), 1e-6) << i;
    }
  }
  auto bad = SimArgs("rover", out + "/bad");
  bad.insert(bad.end(), {"--set", "output.trajectory_formats=tum,bag"});
  const auto rb = RunProcess(bad);
  EXPECT_EQ(rb.exit_code, 1) << rb.output;
  EXPECT_NE(rb.output.find("trajectory_formats"), std::string::npos) << rb.output;
}

}  // namespace
}  // namespace cairn
