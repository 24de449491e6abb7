// The live stream seen through Foxglove's own client: @foxglove/ws-protocol connects to a running
// cairnd, subscribes to every advertised channel and decodes every message with the advertised
// protobuf schema (protobufjs), while 20 more clients subscribe and vanish abruptly.

#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <unistd.h>

#include <filesystem>
#include <thread>

#include <gtest/gtest.h>

#include "tests/support/js_clients.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

int FreeLoopbackPort() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a));
  socklen_t len = sizeof(a);
  getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  close(fd);
  return ntohs(a.sin_port);
}

bool CanConnect(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  a.sin_port = htons(static_cast<uint16_t>(port));
  const bool ok = connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof(a)) == 0;
  close(fd);
  return ok;
}

TEST(CairndLiveStreamTest, FoxgloveClientDecodesEveryChannelWhileOthersVanish) {
  if (!fs::exists(testing::EurocMicro())) GTEST_SKIP() << "missing " << testing::EurocMicro();
  std::string why_not;
  const std::string js = testing::InstallJsClients(&why_not);
  if (js.empty()) GTEST_SKIP() << why_not;
  const int port = FreeLoopbackPort();
  const testing::ScopedTempDir temp("live");
  const std::string out = temp.path();
  testing::ProcessResult daemon;
  std::thread runner([&] {
    testing::ProcessOptions po;
    po.signal = SIGTERM;
    po.signal_when_output_contains = "live stream";
    po.signal_after = std::chrono::milliseconds(9000);
    daemon = testing::RunProcess(
        {testing::BinaryDir() + "/daemon/cairnd", "--config", testing::SourceDir() + "/configs/euroc.yaml",
         "--replay", testing::EurocMicro(), "--out", out, "--set", "live.enabled=true", "--set",
         "live.port=" + std::to_string(port), "--set", "replay.pacing=realtime", "--set", "live.image_every=2", "--set",
         "daemon.status_interval=0.25"},
        po);
  });
  bool up = false;
  for (int i = 0; i < 300 && !up; ++i) {
    up = CanConnect(port);
    if (!up) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  testing::ProcessResult client;
  if (up) {
    client = testing::RunProcess({"/usr/bin/node", js + "/ws_check.mjs",
                                  "ws://127.0.0.1:" + std::to_string(port), "4", "20"});
  }
  runner.join();
  ASSERT_TRUE(up) << daemon.output;
  ASSERT_EQ(daemon.exit_code, 0) << daemon.output;
  ASSERT_EQ(client.exit_code, 0) << client.output;
  const testing::JsonValue r = testing::JsonValue::Parse(client.output);
  EXPECT_EQ(r["serverInfo"].string(), "cairnd euroc-mav");
  EXPECT_TRUE(r["errors"].array().empty()) << client.output;
  // The shipped configuration streams images as JPEG (foxglove.CompressedImage).
  // Sensor channels, and the filter's poses and transforms (foxglove.PoseInFrame, FrameTransform).
  for (const char* topic : {"/imu", "/stereo/info", "/cam0/image/compressed", "/cam1/image/compressed", "/diagnostics",
                            "/pose", "/tf"}) {
    const testing::JsonValue& c = r["channels"][topic];
    EXPECT_GT(c["count"].number(), 0) << topic;
    EXPECT_EQ(c["decodeErrors"].number(), 0) << topic;
    EXPECT_TRUE(c["increasing"].boolean()) << topic;
    EXPECT_FALSE(c["last"].is_null()) << topic;
  }
  const testing::JsonValue& imu = r["channels"]["/imu"];
  ASSERT_GT(imu["count"].number(), 50) << client.output;
  const testing::JsonValue& image = r["channels"]["/cam0/image/compressed"]["lastImage"];
  EXPECT_EQ(image["format"].string(), "jpeg");
  EXPECT_EQ(image["width"].number(), 752);
  EXPECT_EQ(image["height"].number(), 480);
  EXPECT_LT(image["bytes"].number(), 752 * 480 / 3);
  EXPECT_EQ(r["channels"]["/cam0/image"]["count"].number(), 0);  // advertised, not sent
  EXPECT_EQ(r["channels"]["/wheel_odometry"]["schema"].string(), "cairn.msg.WheelOdometrySample");
  EXPECT_EQ(r["channels"]["/pose"]["schema"].string(), "foxglove.PoseInFrame");
  EXPECT_EQ(r["channels"]["/tf"]["schema"].string(), "foxglove.FrameTransform");
  EXPECT_EQ(r["channels"]["/map/submaps"]["schema"].string(), "foxglove.PointCloud");
  EXPECT_EQ(r["channels"]["/map/obstacles"]["schema"].string(), "foxglove.Grid");
  // Live-only views: the SLAM graph (foxglove.SceneUpdate) and the daemon's log (foxglove.Log),
  // whose recent lines a late subscriber receives too, so the start-up line is there.
  const testing::JsonValue& graph = r["channels"]["/graph"];
  EXPECT_EQ(graph["schema"].string(), "foxglove.SceneUpdate");
  EXPECT_GT(graph["count"].number(), 0);
  EXPECT_EQ(graph["decodeErrors"].number(), 0);
  EXPECT_EQ(graph["lastGraph"]["entities"].number(), 2);  // the graph and the robot's trajectory
  EXPECT_EQ(graph["lastGraph"]["id"].string(), "graph/a");
  EXPECT_EQ(graph["lastGraph"]["frame"].string(), "map");
  EXPECT_GE(graph["lastGraph"]["spheres"].number(), 2);  // the first origin and a robot pose at least
  EXPECT_EQ(graph["lastGraph"]["lines"].number(), 2);
  EXPECT_GE(graph["lastGraph"]["texts"].number(), 1);
  const testing::JsonValue& log = r["channels"]["/log"];
  EXPECT_EQ(log["schema"].string(), "foxglove.Log");
  EXPECT_EQ(log["decodeErrors"].number(), 0);
  bool startup_line = false;
  ASSERT_TRUE(log.has("lines")) << client.output;
  for (const testing::JsonValue& line : log["lines"].array()) {
    startup_line = startup_line || line["message"].string().find("live stream (Foxglove WebSocket) on") != std::string::npos;
    EXPECT_EQ(line["name"].string(), "cairnd euroc-mav");
  }
  EXPECT_TRUE(startup_line) << client.output;
  const testing::JsonValue d = testing::JsonValue::ParseFile(out + "/diagnostics.json");
  EXPECT_EQ(d["live_stream"]["port"].number(), port);
  EXPECT_GE(d["live_stream"]["published"].number(), imu["count"].number());
  // Every IMU sample of the 200 Hz stream while subscribed, none thinned: the mean spacing of the
  // received stamps is 5 ms however fast this machine replayed, unless the server had to drop
  // messages for a client that fell behind (a loaded machine), which it counts.
  const double spacing = (std::stod(imu["last"].string()) - std::stod(imu["first"].string())) /
                         (imu["count"].number() - 1.0);
  EXPECT_GT(spacing, 4.75e6) << client.output;
  if (d["live_stream"]["dropped_for_slow_clients"].number() == 0) {
    EXPECT_LT(spacing, 5.25e6) << client.output;
  }
}

}  // namespace
}  // namespace cairn
