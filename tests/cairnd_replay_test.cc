// End-to-end tests of the cairnd binary on the real EuRoC excerpt: counts, determinism, shutdown
// on SIGTERM, and refusal of malformed datasets and configurations before anything is written.

#include <signal.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "common/sanitizers.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;
using testing::ProcessOptions;
using testing::RunProcess;

std::string Cairnd() { return testing::BinaryDir() + "/daemon/cairnd"; }
std::string EurocConfig() { return testing::SourceDir() + "/configs/euroc.yaml"; }

std::string ReadFile(const std::string& path) {
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  return s.str();
}

class CairndReplayTest : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(testing::EurocMicro())) GTEST_SKIP() << "missing " << testing::EurocMicro();
  }
  testing::ProcessResult Run(const std::string& dataset, const std::string& out,
                             std::vector<std::string> extra = {}, ProcessOptions po = {}) {
    std::vector<std::string> argv = {Cairnd(), "--config", EurocConfig(), "--replay", dataset, "--out", out};
    argv.insert(argv.end(), extra.begin(), extra.end());
    return RunProcess(argv, po);
  }
  const testing::ScopedTempDir temp_{"cairnd_out"};
  const std::string out_ = temp_.path();
};

TEST_F(CairndReplayTest, ReplaysEveryImuSampleAndStereoPairInOrder) {
  const auto r = Run(testing::EurocMicro(), out_);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(out_ + "/summary.json");
  EXPECT_EQ(s["stop_reason"].string(), "end_of_data");
  EXPECT_TRUE(s["complete"].boolean());
  EXPECT_EQ(s["replay"]["stereo_pairs"].number(), 95);
  EXPECT_EQ(s["replay"]["unpaired_right"].number(), 4);
  const JsonValue& imu = s["streams"]["imu"];
  EXPECT_EQ(imu["count"].number(), 29120);
  EXPECT_EQ(imu["out_of_order"].number(), 0);
  EXPECT_EQ(imu["duplicates"].number(), 0);
  EXPECT_EQ(imu["gaps"].number(), 0);
  EXPECT_NEAR(imu["mean_rate_hz"].number(), 200.0, 0.01);
  const JsonValue& cam = s["streams"]["stereo"];
  EXPECT_EQ(cam["count"].number(), 95);
  EXPECT_EQ(cam["out_of_order"].number(), 0);
  EXPECT_NEAR(cam["mean_rate_hz"].number(), 20.0, 0.01);
  EXPECT_EQ(s["stereo"]["width"].number(), 752);
  EXPECT_EQ(s["stereo"]["height"].number(), 480);
  for (const auto& [name, dropped] : s["dropped"].object()) EXPECT_EQ(dropped.number(), 0) << name;
  EXPECT_EQ(s["faults"]["total"].number(), 0);
  // The effective configuration is kept with the results and loads again as a configuration.
  const auto again = RunProcess({Cairnd(), "--config", out_ + "/config.yaml", "--out", out_ + "/again"});
  EXPECT_EQ(again.exit_code, 0) << again.output;
}

// A robot profile's CAN bus is a live device: replaying with it must not wait on the bus.
TEST_F(CairndReplayTest, RobotProfileReplaysToTheEndWithoutItsCanBus) {
  const auto r = RunProcess({Cairnd(), "--config", testing::SourceDir() + "/configs/rover.yaml", "--replay",
                             testing::EurocMicro(), "--out", out_, "--set", "replay.pacing=fast", "--set",
                             "live.enabled=false", "--set", "recording.enabled=false", "--set",
                             "replay.deterministic=true"});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(out_ + "/summary.json");
  EXPECT_EQ(s["stop_reason"].string(), "end_of_data");
  EXPECT_EQ(s["streams"]["stereo"]["count"].number(), 95);
}

TEST_F(CairndReplayTest, DeterministicReplayWritesIdenticalSummaries) {
  const testing::ScopedTempDir temp("cairnd_out2");
  const std::string second = temp.path();
  ASSERT_EQ(Run(testing::EurocMicro(), out_).exit_code, 0);
  ASSERT_EQ(Run(testing::EurocMicro(), second).exit_code, 0);
  const std::string a = ReadFile(out_ + "/summary.json");
  ASSERT_FALSE(a.empty());
  EXPECT_EQ(a, ReadFile(second + "/summary.json"));
}

TEST_F(CairndReplayTest, SigtermMidReplayExitsCleanlyWithCompleteOutputs) {
  ProcessOptions po;
  po.signal = SIGTERM;
  po.signal_when_output_contains = "running";
  po.signal_after = std::chrono::milliseconds(1500);
  // Real-time pacing: the 4.7 s of camera data cannot be over when the signal arrives.
  const auto r = Run(testing::EurocMicro(), out_, {"--set", "replay.pacing=realtime"}, po);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  EXPECT_NE(r.output.find("SIGTERM received"), std::string::npos) << r.output;
  const JsonValue s = JsonValue::ParseFile(out_ + "/summary.json");
  EXPECT_EQ(s["stop_reason"].string(), "signal");
  EXPECT_FALSE(s["complete"].boolean());
  const double imu = s["streams"]["imu"]["count"].number();
  EXPECT_GT(imu, 0);
  EXPECT_LT(imu, 29120);
  EXPECT_TRUE(fs::exists(out_ + "/diagnostics.json"));
  // The process's memory at the end, for reading a long mission's growth.
  const JsonValue m = JsonValue::ParseFile(out_ + "/diagnostics.json")["memory"];
  EXPECT_EQ(m["heap_policy"].boolean(), !(CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER));
  EXPECT_GT(m["rss_mb"].number(), 10.0);
  EXPECT_GE(m["peak_rss_mb"].number(), m["rss_mb"].number());
  // A sanitizer's allocator keeps glibc's counters at zero.
  if (!(CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER)) {
    EXPECT_GT(m["heap_in_use_mb"].number(), 1.0);
  }
  EXPECT_GE(m["heap_free_retained_mb"].number(), 0.0);
  EXPECT_GE(m["map_mb"].number(), m["map_composer_mb"].number() + m["submaps_mb"].number());
  EXPECT_GT(m["trajectories_mb"].number(), 0.0);
  EXPECT_EQ(m["simulator_mb"].number(), 0.0);  // a replay streams its dataset
  // Real-time pacing: the latency from an IMU sample's arrival to the estimate at it is measured.
  bool found = false;
  const JsonValue diagnostics = JsonValue::ParseFile(out_ + "/diagnostics.json");
  for (const JsonValue& l : diagnostics["latency"].array()) {
    if (l["stage_input"].string() != "imu_to_estimate") continue;
    found = true;
    EXPECT_GT(l["count"].number(), 0);
    EXPECT_LE(l["count"].number(), imu);
    EXPECT_GT(l["p50_s"].number(), 0.0);
    EXPECT_LE(l["p50_s"].number(), l["p999_s"].number());
    EXPECT_LE(l["p999_s"].number(), l["max_s"].number());
    EXPECT_LE(l["over_1ms"].number(), l["count"].number());
  }
  EXPECT_TRUE(found);
  EXPECT_TRUE(fs::exists(out_ + "/config.yaml"));
  for (const auto& e : fs::directory_iterator(out_)) {
    EXPECT_NE(e.path().extension(), ".tmp") << "half-written file left: " << e.path();
  }
}

// Each broken dataset is refused up front: non-zero exit, a message naming the culprit, and no
// output folder at all.
TEST_F(CairndReplayTest, MalformedDatasetsFailBeforeWritingAnything) {
  struct Case {
    const char* name;
    std::function<std::string(const std::string&)> damage;  // returns the path to expect
  };
  const Case cases[] = {
      {"missing image", [](const std::string& root) {
         const std::string p = root + "/mav0/cam0/data/1403715275262142976.png";
         fs::remove(p);
         return p;
       }},
      {"truncated csv", [](const std::string& root) {
         const std::string p = root + "/mav0/imu0/data.csv";
         fs::resize_file(p, fs::file_size(p) - 20);
         return p;
       }},
      {"bad yaml", [](const std::string& root) {
         const std::string p = root + "/mav0/imu0/sensor.yaml";
         std::ofstream(p) << "rate_hz: {oops\n";
         return p;
       }},
  };
  for (const Case& c : cases) {
    const testing::ScopedTempDir temp("broken");
    const std::string root = temp.path();
    testing::CopyEurocDataset(testing::EurocMicro(), root);
    const std::string culprit = c.damage(root);
    const std::string out = root + "/out";
    const auto r = Run(root, out);
    EXPECT_NE(r.exit_code, 0) << c.name;
    EXPECT_NE(r.output.find(culprit), std::string::npos) << c.name << ":\n" << r.output;
    EXPECT_FALSE(fs::exists(out)) << c.name << ": output written";
  }
}

TEST_F(CairndReplayTest, CorruptImageMidRunIsAFaultNotAnExit) {
  const testing::ScopedTempDir temp("corrupt");
  const std::string root = temp.path();
  testing::CopyEurocDataset(testing::EurocMicro(), root);
  const std::string img = root + "/mav0/cam1/data/1403715274262142976.png";
  fs::remove(img);
  std::ofstream(img) << "not a png";
  const auto r = Run(root, out_);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(out_ + "/summary.json");
  EXPECT_EQ(s["streams"]["stereo"]["count"].number(), 94);
  EXPECT_EQ(s["faults"]["total"].number(), 1);
  EXPECT_EQ(s["faults"]["by_device"]["replay/stereo"]["corrupt_sample"].number(), 1);
  EXPECT_EQ(s["stereo"]["frame_counter_gaps"].number(), 1);
  EXPECT_NE(s["faults"]["first_messages"][0].string().find(img), std::string::npos);
}

TEST_F(CairndReplayTest, ConfigurationErrorsNameFileLineAndKey) {
  const std::string cfg = out_ + "/bad.yaml";
  std::string text = ReadFile(EurocConfig());
  text.replace(text.find("  stereo: 4"), 11, "  stereo: 0\n  sterio: 4");
  std::ofstream(cfg) << text;
  const auto r = RunProcess({Cairnd(), "--config", cfg, "--replay", testing::EurocMicro(), "--out", out_ + "/o"});
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.output.find("key 'queues.stereo' = 0 is outside [2, 1024] frames"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("unknown key 'queues.sterio'"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find(cfg + ":"), std::string::npos);
  EXPECT_FALSE(fs::exists(out_ + "/o"));
  const auto bad_set = RunProcess({Cairnd(), "--config", EurocConfig(), "--set", "queues.imu=1"});
  EXPECT_EQ(bad_set.exit_code, 1);
  EXPECT_NE(bad_set.output.find("--set queues.imu"), std::string::npos) << bad_set.output;
  EXPECT_EQ(RunProcess({Cairnd(), "--bogus"}).exit_code, 2);
}

// Where the system refuses SCHED_FIFO and mlockall (no CAP_SYS_NICE / CAP_IPC_LOCK), the daemon
// says so once and runs at normal priority.
TEST_F(CairndReplayTest, RefusedRealtimeDegradesWithOneWarning) {
  if (!fs::exists("/usr/bin/setpriv")) GTEST_SKIP() << "missing /usr/bin/setpriv";
  const auto r = RunProcess({"/usr/bin/setpriv", "--inh-caps=-sys_nice,-ipc_lock",
                             "--bounding-set=-sys_nice,-ipc_lock", Cairnd(), "--config", EurocConfig(),
                             "--replay", testing::EurocMicro(), "--out", out_});
  ASSERT_EQ(r.exit_code, 0) << r.output;
  size_t warnings = 0;
  for (size_t p = r.output.find("[warning]"); p != std::string::npos; p = r.output.find("[warning]", p + 1)) ++warnings;
  EXPECT_EQ(warnings, 1u) << r.output;
  const JsonValue d = JsonValue::ParseFile(out_ + "/diagnostics.json");
  EXPECT_FALSE(d["executors"][0]["realtime_granted"].boolean());
  EXPECT_EQ(JsonValue::ParseFile(out_ + "/summary.json")["streams"]["imu"]["count"].number(), 29120);
}

}  // namespace
}  // namespace cairn
