// Recording to MCAP and replaying recordings: what cairnd consumed is what it recorded, a replay
// of a deterministic recording reproduces the run (and the recorded sensor messages) byte for byte,
// rotation splits files without losing samples, and a recording cut short by SIGKILL still replays.

#include <signal.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "drivers/mcap/mcap_reader.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;

std::string Cairnd() { return testing::BinaryDir() + "/daemon/cairnd"; }
std::string Config() { return testing::SourceDir() + "/configs/euroc.yaml"; }

// The sensor messages of a recording in file order, one line each (topic, log time, size and a
// hash of the bytes): what a replay of it must record again. The estimates (/pose, /tf) are left
// out: a recording does not carry the sensors' calibration yet, so its replay does not re-run the
// estimation chain.
std::vector<std::string> SensorMessages(const std::string& path) {
  std::vector<std::string> out;
  McapReader reader(path);
  auto scan = reader.Scan([&](const McapChannel& c, const McapMessageView& m) {
    if (c.topic == "/pose" || c.topic == "/tf" || c.topic.starts_with("/map/")) return;
    uint64_t h = 1469598103934665603ull;  // FNV-1a
    for (uint8_t b : m.data) h = (h ^ b) * 1099511628211ull;
    out.push_back(c.topic + " " + std::to_string(m.log_time) + " " + std::to_string(m.data.size()) + " " +
                  std::to_string(h));
  });
  EXPECT_TRUE(scan.ok()) << path << ": " << scan.status().ToString();
  return out;
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
    dir_ = testing::FreshTempDir("recording");
  }
  std::string dir_;
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
  const auto sensors = SensorMessages(dir_ + "/a/recording-000.mcap");
  EXPECT_EQ(sensors.size(), 29120u + 3u * 95u);
  EXPECT_EQ(sensors, SensorMessages(dir_ + "/b/recording-000.mcap"));
}

// PNG recordings are lossless: replaying one and recording raw gives the raw recording of the
// original run byte for byte. JPEG recordings are a fraction of the size and replay whole.
TEST_F(CairndRecordingTest, CompressedImagesReplayPngBitExactAndJpegSmall) {
  ASSERT_EQ(RunCairnd(testing::EurocMicro(), dir_ + "/raw").exit_code, 0);
  const auto png = RunCairnd(testing::EurocMicro(), dir_ + "/png", {"--set", "recording.images.format=png"});
  ASSERT_EQ(png.exit_code, 0) << png.output;
  const JsonValue p = JsonValue::ParseFile(dir_ + "/png/summary.json");
  EXPECT_EQ(p["recording"]["messages"]["/cam0/image/compressed"].number(), 95);
  EXPECT_EQ(p["recording"]["messages"]["/cam1/image/compressed"].number(), 95);
  EXPECT_FALSE(p["recording"]["messages"].has("/cam0/image"));
  const auto again = RunCairnd(dir_ + "/png/recording-000.mcap", dir_ + "/png-raw");
  ASSERT_EQ(again.exit_code, 0) << again.output;
  EXPECT_EQ(SensorMessages(dir_ + "/raw/recording-000.mcap"), SensorMessages(dir_ + "/png-raw/recording-000.mcap"));

  const auto jpeg = RunCairnd(testing::EurocMicro(), dir_ + "/jpeg",
                              {"--set", "recording.images.format=jpeg", "--set", "recording.images.jpeg_quality=90"});
  ASSERT_EQ(jpeg.exit_code, 0) << jpeg.output;
  const auto raw_size = fs::file_size(dir_ + "/raw/recording-000.mcap");
  const auto jpeg_size = fs::file_size(dir_ + "/jpeg/recording-000.mcap");
  EXPECT_LT(jpeg_size * 3, raw_size) << jpeg_size << " vs " << raw_size;  // measured: 3.9x smaller
  const auto replayed = RunCairnd(dir_ + "/jpeg/recording-000.mcap", dir_ + "/jpeg-replay");
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

}  // namespace
}  // namespace cairn
