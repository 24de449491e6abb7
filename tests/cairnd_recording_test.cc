// Recording to MCAP and replaying recordings: what cairnd consumed is what it recorded, a replay
// of a deterministic recording re-estimates with the recorded calibration and reproduces the run
// (every recorded message, the trajectories and the maps) byte for byte, rotation splits files
// without losing samples, and a recording cut short by SIGKILL still replays.

#include <signal.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "io/mcap/mcap_reader.h"
#include "io/mcap/mcap_writer.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;

std::string Cairnd() { return testing::BinaryDir() + "/daemon/cairnd"; }
std::string Config() { return testing::SourceDir() + "/configs/euroc.yaml"; }

bool IsSensorTopic(const std::string& topic) {
  return topic == "/imu" || topic == "/wheel_odometry" || topic == "/stereo/info" || topic.starts_with("/cam");
}

// The messages of a recording in file order, one line each (topic, log time, size and a hash of
// the bytes); `sensors_only` keeps the raw samples a replay consumes.
std::vector<std::string> Messages(const std::string& path, bool sensors_only = false) {
  std::vector<std::string> out;
  McapReader reader(path);
  auto scan = reader.Scan([&](const McapChannel& c, const McapMessageView& m) {
    if (sensors_only && !IsSensorTopic(c.topic)) return;
    uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (uint8_t b : m.data) h = (h ^ b) * 1099511628211ull;
    out.push_back(c.topic + " " + std::to_string(m.log_time) + " " + std::to_string(m.data.size()) + " " +
                  std::to_string(h));
  });
  EXPECT_TRUE(scan.ok()) << path << ": " << scan.status().ToString();
  return out;
}

std::string FileBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  EXPECT_TRUE(in.good()) << "cannot read " << path;
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Copies a recording, replacing its /calibration message by `calibration` (dropped when empty):
// what an older cairnd wrote, or a damaged file.
void RewriteCalibration(const std::string& from, const std::string& to, const std::string& calibration) {
  McapReader reader(from);
  ASSERT_TRUE(reader.Scan(nullptr).ok()) << from;
  // Channels first, as cairnd writes them.
  McapWriter writer;
  ASSERT_TRUE(writer.Open(to, McapWriterOptions{}).ok()) << to;
  std::map<uint16_t, uint16_t> schema_of, channel_of;
  for (const auto& [id, c] : reader.channels()) {
    if (c.topic == "/calibration" && calibration.empty()) continue;
    if (schema_of.count(c.schema_id) == 0) {
      const McapSchema& s = reader.schemas().at(c.schema_id);
      schema_of[c.schema_id] = *writer.AddSchema(s.name, s.encoding, s.data);
    }
    channel_of[id] = *writer.AddChannel(c.topic, c.message_encoding, schema_of[c.schema_id]);
  }
  uint64_t written = 0;
  auto scan = reader.Scan([&](const McapChannel& c, const McapMessageView& m) {
    if (c.topic == "/calibration" && calibration.empty()) return;
    const std::span<const uint8_t> data =
        c.topic == "/calibration" ? std::span<const uint8_t>(reinterpret_cast<const uint8_t*>(calibration.data()),
                                                             calibration.size())
                                  : m.data;
    ASSERT_TRUE(writer.Write(channel_of[c.id], m.sequence, m.log_time, m.publish_time, data).ok());
    ++written;
  });
  ASSERT_TRUE(scan.ok()) << scan.status().ToString();
  ASSERT_GT(written, 0u);
  ASSERT_TRUE(writer.Close().ok());
}

testing::ProcessResult RunCairnd(const std::string& input, const std::string& out,
                           std::vector<std::string> extra = {}, testing::ProcessOptions po = {}) {
  std::vector<std::string> argv = {Cairnd(), "--config", Config(), "--replay", input, "--out", out,
                                   "--set", "recording.enabled=true"};
  argv.insert(argv.end(), extra.begin(), extra.end());
  return testing::RunProcess(argv, po);
}

class CairndRecordingTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(testing::EurocMicro())) GTEST_SKIP() << "missing " << testing::EurocMicro();
  }
  const testing::ScopedTempDir temp_{"recording"};
  const std::string dir_ = temp_.path();
};

TEST_F(CairndRecordingTest, ReplayOfARecordingReproducesTheRunAndTheRecording) {
  const auto first = RunCairnd(testing::EurocMicro(), dir_ + "/a");
  ASSERT_EQ(first.exit_code, 0) << first.output;
  const JsonValue a = JsonValue::ParseFile(dir_ + "/a/summary.json");
  const JsonValue& rec = a["recording"];
  EXPECT_EQ(rec["messages"]["/imu"].number(), a["streams"]["imu"]["count"].number());
  EXPECT_EQ(rec["messages"]["/cam0/image"].number(), 95);
  EXPECT_EQ(rec["messages"]["/cam1/image"].number(), 95);
  EXPECT_EQ(rec["messages"]["/stereo/info"].number(), 95);
  EXPECT_EQ(rec["dropped"].number(), 0);
  EXPECT_EQ(rec["write_errors"].number(), 0);
  EXPECT_EQ(rec["image_codec_failures"].number(), 0);
  EXPECT_EQ(rec["bytes"].number(), static_cast<double>(fs::file_size(dir_ + "/a/recording-000.mcap")));

  const auto second = RunCairnd(dir_ + "/a/recording-000.mcap", dir_ + "/b");
  ASSERT_EQ(second.exit_code, 0) << second.output;
  const JsonValue b = JsonValue::ParseFile(dir_ + "/b/summary.json");
  for (const char* stream : {"imu", "stereo"}) {
    for (const char* key : {"count", "first_time_ns", "last_time_ns", "out_of_order", "duplicates", "max_gap_s"}) {
      EXPECT_EQ(a["streams"][stream][key].number(), b["streams"][stream][key].number()) << stream << "." << key;
    }
  }
  EXPECT_EQ(b["faults"]["total"].number(), 0);
  EXPECT_TRUE(b["complete"].boolean());
  EXPECT_EQ(rec["messages"]["/pose"].number(), a["estimation"]["trajectory_poses"].number());
  EXPECT_EQ(rec["messages"]["/tf"].number(), a["estimation"]["trajectory_poses"].number());
  EXPECT_EQ(rec["messages"]["/calibration"].number(), 1);
  EXPECT_GT(a["estimation"]["trajectory_poses"].number(), 50);
  // The replay ran the estimation chain again, with the recorded calibration, to the same bits.
  EXPECT_EQ(b["estimation"]["trajectory_poses"].number(), a["estimation"]["trajectory_poses"].number());
  EXPECT_EQ(Messages(dir_ + "/a/recording-000.mcap", true).size(), 29120u + 3u * 95u);
  EXPECT_EQ(Messages(dir_ + "/a/recording-000.mcap"), Messages(dir_ + "/b/recording-000.mcap"));
  for (const char* f : {"recording-000.mcap", "trajectory.tum", "vo.tum"}) {
    EXPECT_TRUE(FileBytes(dir_ + "/a/" + f) == FileBytes(dir_ + "/b/" + f)) << f << " differs";
  }
}

// A recording made without a calibration (an older cairnd) still replays its sensors, with a
// warning, and estimates nothing; a calibration that does not decode is refused naming the file.
TEST_F(CairndRecordingTest, RecordingsWithoutOrWithBadCalibration) {
  ASSERT_EQ(RunCairnd(testing::EurocMicro(), dir_ + "/a", {"--set", "recording.compression=lz4"}).exit_code, 0);
  fs::create_directories(dir_ + "/old");
  RewriteCalibration(dir_ + "/a/recording-000.mcap", dir_ + "/old/recording-000.mcap", "");
  const auto old = RunCairnd(dir_ + "/old/recording-000.mcap", dir_ + "/old-replay");
  ASSERT_EQ(old.exit_code, 0) << old.output;
  EXPECT_NE(old.output.find("carries no calibration"), std::string::npos) << old.output;
  const JsonValue o = JsonValue::ParseFile(dir_ + "/old-replay/summary.json");
  EXPECT_EQ(o["streams"]["stereo"]["count"].number(), 95);
  EXPECT_FALSE(o.has("estimation") && o["estimation"].has("trajectory_poses") &&
               o["estimation"]["trajectory_poses"].number() > 0);
  EXPECT_EQ(Messages(dir_ + "/a/recording-000.mcap", true), Messages(dir_ + "/old-replay/recording-000.mcap", true));

  fs::create_directories(dir_ + "/bad");
  RewriteCalibration(dir_ + "/a/recording-000.mcap", dir_ + "/bad/recording-000.mcap", "\xff\xff not a message");
  const auto bad = RunCairnd(dir_ + "/bad/recording-000.mcap", dir_ + "/bad-replay");
  EXPECT_EQ(bad.exit_code, 1) << bad.output;
  EXPECT_NE(bad.output.find("bad/recording-000.mcap /calibration"), std::string::npos) << bad.output;
}

// PNG recordings are lossless: replaying one and recording raw gives the raw recording of the
// original run byte for byte. JPEG recordings are a fraction of the size and replay whole.
TEST_F(CairndRecordingTest, CompressedImagesReplayPngBitExactAndJpegSmall) {
  // What is recorded does not depend on the estimation: without VO and the graph the five runs
  // take a third less time (under the sanitizers, most of this test's).
  const std::vector<std::string> no_vo = {"--set", "vo.enabled=false", "--set", "graph.enabled=false"};
  const auto with = [&](std::vector<std::string> a) {
    a.insert(a.end(), no_vo.begin(), no_vo.end());
    return a;
  };
  ASSERT_EQ(RunCairnd(testing::EurocMicro(), dir_ + "/raw", no_vo).exit_code, 0);
  const auto png = RunCairnd(testing::EurocMicro(), dir_ + "/png", with({"--set", "recording.images.format=png"}));
  ASSERT_EQ(png.exit_code, 0) << png.output;
  const JsonValue p = JsonValue::ParseFile(dir_ + "/png/summary.json");
  EXPECT_EQ(p["recording"]["messages"]["/cam0/image/compressed"].number(), 95);
  EXPECT_EQ(p["recording"]["messages"]["/cam1/image/compressed"].number(), 95);
  EXPECT_FALSE(p["recording"]["messages"].has("/cam0/image"));
  const auto again = RunCairnd(dir_ + "/png/recording-000.mcap", dir_ + "/png-raw", no_vo);
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(Messages(dir_ + "/raw/recording-000.mcap"), Messages(dir_ + "/png-raw/recording-000.mcap"));

  const auto jpeg = RunCairnd(testing::EurocMicro(), dir_ + "/jpeg",
                              with({"--set", "recording.images.format=jpeg", "--set", "recording.images.jpeg_quality=90"}));
  ASSERT_EQ(jpeg.exit_code, 0) << jpeg.output;
  const auto raw_size = fs::file_size(dir_ + "/raw/recording-000.mcap");
  const auto jpeg_size = fs::file_size(dir_ + "/jpeg/recording-000.mcap");
  EXPECT_LT(jpeg_size * 3, raw_size) << jpeg_size << " vs " << raw_size;  // measured: 3.9x smaller
  const auto replayed = RunCairnd(dir_ + "/jpeg/recording-000.mcap", dir_ + "/jpeg-replay", no_vo);
  ASSERT_EQ(replayed.exit_code, 0) << replayed.output;
  const JsonValue r = JsonValue::ParseFile(dir_ + "/jpeg-replay/summary.json");
  EXPECT_EQ(r["streams"]["stereo"]["count"].number(), 95);
  EXPECT_EQ(r["stereo"]["width"].number(), 752);
  EXPECT_EQ(r["faults"]["total"].number(), 0);
}

TEST_F(CairndRecordingTest, RotationSplitsFilesAndAFolderReplaysWhole) {
  const auto r = RunCairnd(testing::EurocMicro(), dir_ + "/rot",
                     {"--set", "recording.rotate_size=8388608", "--set", "recording.chunk_size=1048576",
                      "--set", "recording.compression=lz4"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(dir_ + "/rot/summary.json");
  const size_t files = s["recording"]["files"].array().size();
  EXPECT_GE(files, 4u);
  for (size_t i = 0; i < files; ++i) {
    EXPECT_LE(fs::file_size(dir_ + "/rot/" + s["recording"]["files"][i].string()), 8388608u + 2 * 1048576u);
  }
  const auto again = RunCairnd(dir_ + "/rot", dir_ + "/rot-replay", {"--set", "recording.enabled=false"});
  ASSERT_EQ(again.exit_code, 0) << again.output;
  const JsonValue t = JsonValue::ParseFile(dir_ + "/rot-replay/summary.json");
  EXPECT_EQ(t["streams"]["imu"]["count"].number(), 29120);
  EXPECT_EQ(t["streams"]["stereo"]["count"].number(), 95);
  EXPECT_EQ(t["streams"]["imu"]["out_of_order"].number(), 0);
}

TEST_F(CairndRecordingTest, RecordingCutShortBySigkillStillReplays) {
  testing::ProcessOptions po;
  po.signal = SIGKILL;
  po.signal_when_output_contains = "running";
  po.signal_after = std::chrono::milliseconds(2500);
  // Real-time pacing with small chunks: several chunks are on disk when the process dies.
  const auto r = RunCairnd(testing::EurocMicro(), dir_ + "/killed",
                     {"--set", "replay.pacing=realtime", "--set", "recording.chunk_size=65536"}, po);
  ASSERT_EQ(r.term_signal, SIGKILL) << r.output;
  EXPECT_FALSE(fs::exists(dir_ + "/killed/summary.json"));
  const auto replay = RunCairnd(dir_ + "/killed", dir_ + "/after", {"--set", "recording.enabled=false"});
  ASSERT_EQ(replay.exit_code, 0) << replay.output;
  const JsonValue s = JsonValue::ParseFile(dir_ + "/after/summary.json");
  EXPECT_GT(s["streams"]["imu"]["count"].number(), 100);
  EXPECT_GT(s["streams"]["stereo"]["count"].number(), 5);
  EXPECT_EQ(s["streams"]["imu"]["out_of_order"].number(), 0);
  EXPECT_NE(s["faults"]["first_messages"][0].string().find("cut short"), std::string::npos);
}

TEST_F(CairndRecordingTest, BadRecordingsAreRefusedBeforeAnythingIsWritten) {
  std::ofstream(dir_ + "/fake.mcap") << "definitely not mcap";
  const auto bad = RunCairnd(dir_ + "/fake.mcap", dir_ + "/o1");
  EXPECT_EQ(bad.exit_code, 1);
  EXPECT_NE(bad.output.find("not an MCAP file"), std::string::npos) << bad.output;
  EXPECT_FALSE(fs::exists(dir_ + "/o1"));
  // Replaying a recording into its own folder with recording on would overwrite it.
  ASSERT_EQ(RunCairnd(testing::EurocMicro(), dir_ + "/self", {"--set", "recording.compression=none"}).exit_code, 0);
  const auto self = RunCairnd(dir_ + "/self", dir_ + "/self");
  EXPECT_EQ(self.exit_code, 1);
  EXPECT_NE(self.output.find("overwrite"), std::string::npos) << self.output;
}

// A simulated rover (wheels, dense stereo, mapping, frame switches made by submap partitioning):
// the replay of its recording reproduces every estimate, submap and map byte for byte.
TEST(CairndRecordingSimTest, SimulatedRoverRecordingReplaysToTheSameEstimatesAndMaps) {
  const testing::ScopedTempDir temp("recording-sim");
  const std::string dir = temp.path();
  const std::string config = testing::SourceDir() + "/configs/rover.yaml";
  const std::vector<std::string> common = {"--set", "replay.pacing=fast", "--set", "replay.deterministic=true",
                                           "--set", "recording.enabled=true", "--set", "recording.images.format=png",
                                           "--set", "live.enabled=false"};
  std::vector<std::string> sim = {Cairnd(), "--config", config, "--sim", "--out", dir + "/a", "--set", "sim.duration=6",
                              "--set", "sim.image_scale=0.5"};
  sim.insert(sim.end(), common.begin(), common.end());
  const auto a = testing::RunProcess(sim);
  ASSERT_EQ(a.exit_code, 0) << a.output;
  std::vector<std::string> replay = {Cairnd(), "--config", config, "--replay", dir + "/a/recording-000.mcap",
                                     "--out", dir + "/b"};
  replay.insert(replay.end(), common.begin(), common.end());
  const auto b = testing::RunProcess(replay);
  ASSERT_EQ(b.exit_code, 0) << b.output;
  const JsonValue sa = JsonValue::ParseFile(dir + "/a/summary.json");
  EXPECT_GT(sa["streams"]["wheel_odometry"]["count"].number(), 500);
  EXPECT_GE(sa["mapping"]["submaps"]["written"].number(), 1);
  EXPECT_EQ(Messages(dir + "/a/recording-000.mcap"), Messages(dir + "/b/recording-000.mcap"));
  for (const char* f : {"trajectory.tum", "vo.tum", "global_trajectory.tum", "graph.g2o", "map.ply", "map.bt",
                        "obstacles.png", "submaps/rover-000000.submap"}) {
    EXPECT_TRUE(FileBytes(dir + "/a/" + f) == FileBytes(dir + "/b/" + f)) << f << " differs";
  }
}

}  // namespace
}  // namespace cairn
