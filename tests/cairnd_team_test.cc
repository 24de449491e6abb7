// cairnd as a team: two simulated robots, each its own process, exchanging over loopback through
// ZeroMQ with CURVE keys made by `cairn keys generate`, as the demo runs them; and an intruder
// whose key the team file does not list, which gets nothing and injects nothing.

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <sstream>
#include <thread>

#include <gtest/gtest.h>

#include "estimation/eval/team_agreement.h"
#include "tests/support/json_value.h"
#include "tests/support/loopback_loss.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/tcp_link_proxy.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;
using testing::JsonValue;
using testing::ProcessResult;
using testing::RunProcess;

std::string Cairnd() { return testing::BinaryDir() + "/daemon/cairnd"; }
std::string Cairn() { return testing::BinaryDir() + "/tools/cairn"; }
std::string Config(const std::string& profile) { return testing::SourceDir() + "/configs/" + profile + ".yaml"; }

std::string PublicKey(const std::string& pub_file) {
  std::ifstream in(pub_file);
  std::string word, key;
  while (in >> word) {
    if (word == "public-key" && in >> key) return key;
  }
  return "";
}

struct Member {
  std::string name;
  std::string letter;
  std::string profile;
  int port = 0;
};

// Writes a team file of `members` with the keys found in `keys_dir`.
void WriteTeam(const std::string& path, const std::vector<Member>& members, const std::string& keys_dir) {
  std::ofstream out(path);
  out << "members:\n";
  for (const Member& m : members) {
    out << "  - {name: " << m.name << ", letter: " << m.letter << ", address: \"tcp://127.0.0.1:" << m.port
        << "\", public_key: \"" << PublicKey(keys_dir + "/" + m.name + ".pub") << "\"}\n";
  }
}

// A key pair per name in `keys_dir` (created), as `cairn keys generate` makes them.
void GenerateKeys(const std::string& keys_dir, const std::vector<std::string>& names) {
  fs::create_directories(keys_dir);
  for (const std::string& name : names) {
    const ProcessResult r = RunProcess({Cairn(), "keys", "generate", "--name", name, "--dir", keys_dir});
    ASSERT_EQ(r.exit_code, 0) << r.output;
  }
}

// Ports of this test process (`slot` 0-7 of its block), apart from other tests' processes.
int TeamPort(int slot) { return 20000 + static_cast<int>(getpid() % 2000) * 8 + slot; }

// A team of a rover ('a') and a hexacopter ('b'): their keys in dir/keys, dir/team.yaml.
void WriteRoverAndHexacopter(const std::string& dir, int slot, Member* rover, Member* hexacopter) {
  ASSERT_NO_FATAL_FAILURE(GenerateKeys(dir + "/keys", {"rover", "hexacopter"}));
  *rover = Member{"rover", "a", "rover", TeamPort(slot)};
  *hexacopter = Member{"hexacopter", "b", "hexacopter", TeamPort(slot) + 1};
  WriteTeam(dir + "/team.yaml", {*rover, *hexacopter}, dir + "/keys");
}

std::vector<std::string> TeamArgs(const Member& m, const std::string& team_file, const std::string& key_file,
                                  const std::string& out, double duration = 6.0) {
  return {Cairnd(), "--config", Config(m.profile), "--sim", "--out", out,
          "--set", "sim.duration=" + std::to_string(duration), "--set", "sim.image_scale=0.25", "--set", "sim.robots=rover,hexacopter",
          "--set", "replay.pacing=fast", "--set", "replay.deterministic=true",
          "--set", "live.enabled=false", "--set", "recording.enabled=false",
          "--set", "robot.name=" + m.name, "--set", "graph.optimizer.own_robot=" + m.letter,
          "--set", "team.enabled=true", "--set", "team.members_file=" + team_file,
          "--set", "team.secret_key_file=" + key_file, "--set", "team.linger=60",
          "--log-level", "warn"};
}

const JsonValue* RobotEntry(const JsonValue& team, const std::string& name) {
  for (const JsonValue& r : team["robots"].array()) {
    if (r["name"].string() == name) return &r;
  }
  return nullptr;
}

TEST(CairndTeamTest, TwoRobotsHoldEachOthersItemsOnceAndAnIntruderGetsNothing) {
  const testing::ScopedTempDir temp("cairnd_team");
  const std::string dir = temp.path();
  const std::string keys = dir + "/keys";
  const std::string intruder_keys = dir + "/intruder_keys";
  ASSERT_NO_FATAL_FAILURE(GenerateKeys(keys, {"rover", "hexacopter"}));
  // The intruder knows the team's addresses and public keys, but its own key is not listed.
  ASSERT_NO_FATAL_FAILURE(GenerateKeys(intruder_keys, {"rover2"}));
  for (const std::string name : {"rover", "hexacopter"}) {
    fs::copy_file(keys + "/" + name + ".pub", intruder_keys + "/" + name + ".pub");
  }
  const int base = TeamPort(0);
  const Member rover{"rover", "a", "rover", base};
  const Member hexacopter{"hexacopter", "b", "hexacopter", base + 1};
  const Member intruder{"rover2", "c", "rover", base + 2};
  WriteTeam(dir + "/team.yaml", {rover, hexacopter}, keys);
  WriteTeam(dir + "/intruder.yaml", {rover, hexacopter, intruder}, intruder_keys);

  testing::ProcessOptions options;
  options.timeout = std::chrono::minutes(8);
  ProcessResult results[3];
  std::thread runs[3];
  runs[0] = std::thread([&] {
    results[0] = RunProcess(TeamArgs(rover, dir + "/team.yaml", keys + "/rover.key", dir + "/rover"), options);
  });
  runs[1] = std::thread([&] {
    results[1] = RunProcess(TeamArgs(hexacopter, dir + "/team.yaml", keys + "/hexacopter.key", dir + "/hexacopter"),
                            options);
  });
  runs[2] = std::thread([&] {
    // It never settles (nobody answers): a short linger.
    auto args = TeamArgs(intruder, dir + "/intruder.yaml", intruder_keys + "/rover2.key", dir + "/rover2");
    args.push_back("--set");
    args.push_back("team.linger=3");
    args.push_back("--set");
    args.push_back("sim.robots=rover,hexacopter,rover2");
    results[2] = RunProcess(args, options);
  });
  for (std::thread& t : runs) t.join();
  for (const ProcessResult& r : results) ASSERT_EQ(r.exit_code, 0) << r.output;

  const JsonValue a = JsonValue::ParseFile(dir + "/rover/team.json");
  const JsonValue b = JsonValue::ParseFile(dir + "/hexacopter/team.json");
  const JsonValue c = JsonValue::ParseFile(dir + "/rover2/team.json");
  EXPECT_TRUE(a["settled"].boolean());
  EXPECT_TRUE(b["settled"].boolean());
  // Every item a robot published is held by the other, once: counted by kind on both sides.
  for (const auto& [self, other, other_name] :
       {std::tuple(&a, &b, std::string("hexacopter")), std::tuple(&b, &a, std::string("rover"))}) {
    const JsonValue* entry = RobotEntry(*self, other_name);
    ASSERT_NE(entry, nullptr);
    EXPECT_TRUE((*entry)["heard"].boolean());
    const JsonValue& sent = (*other)["exchange"]["sent_items"];
    ASSERT_GT(sent.object().size(), 0u);
    for (const std::string kind : {"run_start", "frame_switch", "poses", "submap"}) {
      if (!sent.has(kind)) continue;
      EXPECT_EQ((*entry)["items"][kind].number(), sent[kind].number()) << other_name << " " << kind;
    }
    EXPECT_EQ((*self)["peers"][0]["refused_messages"].number(), 0);
    EXPECT_EQ((*self)["peers"][0]["queued_items"].number(), 0);
    EXPECT_GT((*self)["peers"][0]["sent_bytes_per_s"].number(), 0.0);
    EXPECT_EQ((*self)["exchange"]["decode_errors"].number(), 0);
  }
  // The intruder was refused by both, heard from nobody, and nothing of it is in their logs.
  EXPECT_GT(a["transport"]["refused_unknown_key"].number() + b["transport"]["refused_unknown_key"].number(), 0);
  EXPECT_EQ(c["transport"]["received_messages"].number(), 0);
  for (const JsonValue& p : c["peers"].array()) EXPECT_FALSE(p["heard"].boolean());
  for (const JsonValue* self : {&a, &b}) EXPECT_EQ(RobotEntry(*self, "rover2"), nullptr);
  for (const std::string store : {"/rover/exchange", "/hexacopter/exchange"}) {
    for (const auto& f : fs::directory_iterator(dir + store)) {
      EXPECT_EQ(f.path().filename().string().find("rover2"), std::string::npos) << f.path();
    }
  }
}

// How `viewer`'s graph places each robot of `robots` (global_trajectory_<robot>.tum); robots whose
// file is missing are left out, and the caller checks what it needs.
TeamView ReadView(const std::string& dir, const std::string& viewer, const std::vector<std::string>& robots) {
  TeamView view{viewer, {}};
  for (const std::string& robot : robots) {
    auto t = TrajectoryIo::Read(dir + "/" + viewer + "/global_trajectory_" + robot + ".tum", TrajectoryFormat::kTum);
    if (t.ok()) view.robots.emplace_back(robot, *t);
  }
  return view;
}

// Graphs agree where the team is: every robot's pose within 1 mm and 0.01 deg, after one rigid
// alignment per graph.
void ExpectAgreement(const std::vector<TeamView>& views, int min_poses) {
  auto agreement = CompareTeamViews(views);
  ASSERT_TRUE(agreement.ok()) << agreement.status().ToString();
  EXPECT_GT(agreement->compared_poses, min_poses);
  EXPECT_LT(agreement->max_position, 1e-3) << agreement->worst_robot << " as " << agreement->worst_viewer << " places it";
  EXPECT_LT(agreement->max_rotation_deg, 0.01);
  std::printf("graphs agree to %.3f mm, %.4f deg over %d poses\n", 1e3 * agreement->max_position,
              agreement->max_rotation_deg, agreement->compared_poses);
}

double ItemCount(const JsonValue& robot) {
  double n = 0;
  for (const auto& [kind, count] : robot["items"].object()) n += count.number();
  return n;
}

// SIGKILL mid-run, then the same cairnd again on the same disk: the teammate ends up with every
// item of both runs once, and the second run knows it is the robot's second incarnation.
TEST(CairndTeamTest, ARobotKilledAndRestartedLosesAndDuplicatesNothing) {
  const testing::ScopedTempDir temp("cairnd_team_kill");
  const std::string dir = temp.path();
  const std::string keys = dir + "/keys";
  Member rover, hexacopter;
  ASSERT_NO_FATAL_FAILURE(WriteRoverAndHexacopter(dir, 4, &rover, &hexacopter));
  testing::ProcessOptions options;
  options.timeout = std::chrono::minutes(8);
  ProcessResult killed, restarted, teammate;
  std::thread team_thread([&] {
    teammate = RunProcess(TeamArgs(hexacopter, dir + "/team.yaml", keys + "/hexacopter.key", dir + "/hexacopter"),
                          options);
  });
  testing::ProcessOptions kill = options;
  kill.signal = SIGKILL;
  // Once the status line shows the link carrying items both ways, and a little later.
  kill.signal_when_output_contains = "kB, received";
  kill.signal_after = std::chrono::milliseconds(2000);
  // A mission long enough to be killed in its middle; the second incarnation runs a short one.
  auto status_args = TeamArgs(rover, dir + "/team.yaml", keys + "/rover.key", dir + "/rover", 30.0);
  status_args.insert(status_args.end(), {"--set", "daemon.status_interval=0.2", "--log-level", "debug"});
  killed = RunProcess(status_args, kill);
  restarted = RunProcess(TeamArgs(rover, dir + "/team.yaml", keys + "/rover.key", dir + "/rover", 4.0), options);
  team_thread.join();
  ASSERT_EQ(killed.term_signal, SIGKILL) << killed.output;
  ASSERT_EQ(restarted.exit_code, 0) << restarted.output;
  ASSERT_EQ(teammate.exit_code, 0) << teammate.output;

  const JsonValue a = JsonValue::ParseFile(dir + "/rover/team.json");
  const JsonValue b = JsonValue::ParseFile(dir + "/hexacopter/team.json");
  EXPECT_TRUE(a["settled"].boolean());
  EXPECT_TRUE(b["settled"].boolean());
  EXPECT_EQ(a["incarnation"].number(), 1);
  EXPECT_GT(a["exchange"]["earlier_run_items"].number(), 0);  // at least its run start
  const JsonValue* rover_at_b = RobotEntry(b, "rover");
  const JsonValue* rover_at_a = RobotEntry(a, "rover");
  ASSERT_NE(rover_at_b, nullptr);
  ASSERT_NE(rover_at_a, nullptr);
  EXPECT_EQ((*rover_at_b)["items"]["run_start"].number(), 2);  // both runs
  // The run before the kill is a run of its own in both graphs, the restarted robot's too, once it
  // sent estimates (killed early, under a sanitizer, it may have sent only its run start).
  EXPECT_EQ((*rover_at_a)["earlier_runs"].array().size(), (*rover_at_b)["earlier_runs"].array().size());
  EXPECT_LE((*rover_at_a)["earlier_runs"].array().size(), 1u);
  // The teammate holds exactly what the rover's store holds of the rover, over both runs.
  EXPECT_EQ(ItemCount(*rover_at_b), ItemCount(*rover_at_a));
  EXPECT_EQ(ItemCount(*RobotEntry(a, "hexacopter")), ItemCount(*RobotEntry(b, "hexacopter")));
  EXPECT_EQ(b["exchange"]["decode_errors"].number(), 0);
  EXPECT_EQ(a["exchange"]["store_errors"].number(), 0);
}

// The item store on a full disk: the errors are counted and named, the items stored before stay,
// and the robot goes on estimating to the end of its data.
TEST(CairndTeamTest, AFullStoreDiskIsReportedAndTheRobotKeepsEstimating) {
  if (geteuid() != 0) GTEST_SKIP() << "needs root to mount a small tmpfs";
  const testing::ScopedTempDir temp("cairnd_team_full");
  const std::string dir = temp.path();
  const std::string store = dir + "/store";
  fs::create_directories(store);
  if (RunProcess({"/usr/bin/mount", "-t", "tmpfs", "-o", "size=8k", "tmpfs", store}).exit_code != 0) {
    GTEST_SKIP() << "cannot mount a tmpfs here";
  }
  struct Unmount {
    std::string path;
    ~Unmount() { RunProcess({"/usr/bin/umount", path}); }
  } unmount{store};
  const std::string keys = dir + "/keys";
  Member rover, hexacopter;
  ASSERT_NO_FATAL_FAILURE(WriteRoverAndHexacopter(dir, 6, &rover, &hexacopter));
  auto args = TeamArgs(rover, dir + "/team.yaml", keys + "/rover.key", dir + "/rover", 20.0);
  // Alone (the teammate never comes): only its own items, which fill its 8 KB soon.
  args.insert(args.end(), {"--set", "team.store_dir=" + store, "--set", "team.linger=1"});
  testing::ProcessOptions options;
  options.timeout = std::chrono::minutes(8);
  const ProcessResult r = RunProcess(args, options);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  const JsonValue s = JsonValue::ParseFile(dir + "/rover/summary.json");
  EXPECT_EQ(s["stop_reason"].string(), "end_of_data");
  EXPECT_TRUE(fs::exists(dir + "/rover/global_trajectory.tum"));
  const JsonValue t = JsonValue::ParseFile(dir + "/rover/team.json");
  EXPECT_GT(t["exchange"]["store_errors"].number(), 0);
  ASSERT_GT(t["errors"].array().size(), 0u);
  EXPECT_NE(t["errors"][0].string().find(store), std::string::npos) << t["errors"][0].string();
  // What was stored before the disk filled is still there, whole: a new process reads it back.
  const JsonValue* self = RobotEntry(t, "rover");
  ASSERT_NE(self, nullptr);
  EXPECT_GT(ItemCount(*self), 0);
}

// Stopped by a signal (systemctl stop), a robot whose teammate never answers lingers only
// team.stop_linger, not team.linger: the service's stop timeout would kill it before it wrote its
// outputs. A second signal ends the linger at once.
TEST(CairndTeamTest, AStopSignalBoundsTheTeamsLingerAndASecondOneEndsIt) {
  const testing::ScopedTempDir temp("cairnd_team_stop");
  const std::string dir = temp.path();
  const std::string keys = dir + "/keys";
  Member rover, hexacopter;
  ASSERT_NO_FATAL_FAILURE(WriteRoverAndHexacopter(dir, 0, &rover, &hexacopter));
  const auto run = [&](const std::string& out, const std::string& stop_linger, bool twice) {
    auto args = TeamArgs(rover, dir + "/team.yaml", keys + "/rover.key", out, 60.0);
    *std::find(args.begin(), args.end(), "team.linger=60") = "team.linger=3600";
    args.insert(args.end(), {"--set", "team.stop_linger=" + stop_linger, "--log-level", "info"});
    testing::ProcessOptions options;
    // Without the bound, the linger (an hour) outlasts this and the test fails.
    options.timeout = std::chrono::minutes(4);
    options.signal = SIGTERM;
    options.signal_when_output_contains = "running";
    options.signal_after = std::chrono::milliseconds(1500);
    if (twice) options.signal_again_when_output_contains = "team: exchanging until";
    return RunProcess(args, options);
  };
  const ProcessResult bounded = run(dir + "/bounded", "2", false);
  ASSERT_EQ(bounded.exit_code, 0) << bounded.output;
  EXPECT_EQ(JsonValue::ParseFile(dir + "/bounded/summary.json")["stop_reason"].string(), "signal");
  const JsonValue t = JsonValue::ParseFile(dir + "/bounded/team.json");
  EXPECT_FALSE(t["settled"].boolean());
  EXPECT_EQ(t["linger"]["ended"].string(), "time");
  EXPECT_TRUE(fs::exists(dir + "/bounded/global_trajectory.tum"));

  const ProcessResult cut = run(dir + "/cut", "3600", true);
  ASSERT_EQ(cut.exit_code, 0) << cut.output;
  EXPECT_NE(cut.output.find("SIGTERM received again: ending the team's linger"), std::string::npos)
      << cut.output;
  EXPECT_EQ(JsonValue::ParseFile(dir + "/cut/team.json")["linger"]["ended"].string(), "cut");
  EXPECT_TRUE(fs::exists(dir + "/cut/global_trajectory.tum"));
}

// Deployed from the lander, every robot sees its tags while it initializes: each robot's
// sightings (o factors on the one lander variable), its own and its teammates', are factors in the
// graph of the robot whose output is `out`. They tie the robots' subgraphs together.
void ExpectLanderFactorsOfEveryone(const std::string& out, const std::vector<Member>& team) {
  std::ifstream csv(out + "/detections.csv");
  ASSERT_TRUE(csv.good()) << out;
  std::string line;
  std::vector<int> factors(team.size(), 0);
  while (std::getline(csv, line)) {
    if (!line.ends_with(",factor")) continue;
    for (size_t k = 0; k < team.size(); ++k) {
      factors[k] += line.find("," + team[k].name + ",lander,1,") != std::string::npos;
    }
  }
  for (size_t k = 0; k < team.size(); ++k) EXPECT_GT(factors[k], 0) << out << " has no factor from " << team[k].name;
  const JsonValue s = JsonValue::ParseFile(out + "/summary.json");
  EXPECT_GT(s["detection"]["usable"].number(), 0) << out;
}

// `cairn summary` puts each robot's bytes sent over its links per second of its mission (its
// longest stream), as team.json and summary.json count them.
void ExpectSummaryRates(const std::string& dir, const std::vector<Member>& team) {
  std::vector<std::string> args = {Cairn(), "summary"};
  for (const Member& m : team) args.push_back(dir + "/" + m.name);
  const ProcessResult summary = RunProcess(args);
  ASSERT_EQ(summary.exit_code, 0) << summary.output;
  for (const Member& m : team) {
    const JsonValue t = JsonValue::ParseFile(dir + "/" + m.name + "/team.json");
    double sent = 0.0;
    for (const JsonValue& peer : t["peers"].array()) sent += peer["sent_bytes"].number();
    const size_t links = t["peers"].array().size();
    double seconds = 0.0;
    const JsonValue streams = JsonValue::ParseFile(dir + "/" + m.name + "/summary.json")["streams"];
    for (const auto& [name, stream] : streams.object()) {
      if (stream.has("duration_s")) seconds = std::max(seconds, stream["duration_s"].number());
    }
    ASSERT_GT(seconds, 0.0) << m.name;
    ASSERT_GT(links, 0u) << m.name;
    char line[200];
    std::snprintf(line, sizeof(line),
                  "sent per second of the %.0f s mission: %.2f KB/s per link (mean over %zu), %.2f KB/s over all links",
                  seconds, sent / 1e3 / seconds / static_cast<double>(links), links, sent / 1e3 / seconds);
    EXPECT_NE(summary.output.find(line), std::string::npos) << line << "\n" << summary.output;
  }
}

// The team's faults all in one run: 30 % of the packets lost at random, a 2 s one-way delay on
// every link, one robot cut off from both others for 60 s, and one robot SIGKILLed and started
// again. All three are deployed from the lander, whose tags they see while they initialize. After
// the links heal, every robot holds every item of every run once, every robot's graph has factors
// from everyone's sightings of the lander, and the three graphs, tied through it, agree where the
// team is.
TEST(CairndTeamTest, FaultsAllInOneRunLoseNothingAndTheGraphsAgreeAfterHealing) {
  const int base = 30000 + static_cast<int>(getpid() % 2000) * 16;
  const int kRobots = 3;
  const auto proxy_port = [&](int from, int to) { return base + kRobots + kRobots * from + to; };
  std::vector<int> proxy_ports;
  for (int x = 0; x < kRobots; ++x) {
    for (int y = 0; y < kRobots; ++y) {
      if (x != y) proxy_ports.push_back(proxy_port(x, y));
    }
  }
  testing::LoopbackLoss loss(proxy_ports, 30);
  if (!loss.why_not().empty()) GTEST_SKIP() << loss.why_not();
  const testing::ScopedTempDir temp("cairnd_team_faults");
  const std::string dir = temp.path();
  const std::string keys = dir + "/keys";
  const std::vector<Member> team = {{"rover", "a", "rover", base}, {"hexacopter", "b", "hexacopter", base + 1},
                                    {"rover2", "c", "rover", base + 2}};
  ASSERT_NO_FATAL_FAILURE(GenerateKeys(keys, {"rover", "hexacopter", "rover2"}));
  // Robot x reaches robot y only through its own link x -> y, so each has a team file of its own.
  std::map<std::pair<int, int>, std::unique_ptr<testing::TcpLinkProxy>> links;
  for (int x = 0; x < kRobots; ++x) {
    std::vector<Member> seen_from_x = team;
    for (int y = 0; y < kRobots; ++y) {
      if (x == y) continue;
      auto& link = links[std::make_pair(x, y)];
      link = std::make_unique<testing::TcpLinkProxy>(proxy_port(x, y), team[y].port, std::chrono::seconds(2));
      ASSERT_TRUE(link->listening()) << "port " << proxy_port(x, y);
      seen_from_x[y].port = proxy_port(x, y);
    }
    WriteTeam(dir + "/team_" + team[x].name + ".yaml", seen_from_x, keys);
  }
  const auto args_of = [&](int x) {
    auto args = TeamArgs(team[x], dir + "/team_" + team[x].name + ".yaml", keys + "/" + team[x].name + ".key",
                         dir + "/" + team[x].name, 8.0);
    *std::find(args.begin(), args.end(), "sim.robots=rover,hexacopter") = "sim.robots=rover,hexacopter,rover2";
    *std::find(args.begin(), args.end(), "team.linger=60") = "team.linger=400";
    // The hexacopter sees the lander's 0.32 m tag from 3.6 m, the rovers theirs from 2.6 m: at
    // half resolution all of them are usable sightings.
    *std::find(args.begin(), args.end(), "sim.image_scale=0.25") = "sim.image_scale=0.5";
    // A link with seconds of delay: heartbeats wait for a round trip through lost packets.
    args.insert(args.end(), {"--set", "sim.deploy_from_lander=true", "--set", "team.transport.heartbeat_interval=2",
                             "--set", "team.transport.heartbeat_timeout=30"});
    return args;
  };
  testing::ProcessOptions options;
  options.timeout = std::chrono::minutes(14);
  ProcessResult results[kRobots], killed;
  std::vector<std::thread> runs;
  for (int x : {0, 2}) runs.emplace_back([&, x] { results[x] = RunProcess(args_of(x), options); });
  runs.emplace_back([&] {
    // Killed in the middle of its mission, with items stored and on their way, then started again.
    testing::ProcessOptions kill = options;
    kill.signal = SIGKILL;
    kill.signal_when_output_contains = "team exchange:";  // its store is open, its run begun
    kill.signal_after = std::chrono::milliseconds(3000);
    auto first_args = args_of(1);
    first_args.insert(first_args.end(), {"--log-level", "info"});
    killed = RunProcess(first_args, kill);
    results[1] = RunProcess(args_of(1), options);
  });
  // rover2 drops out 3 s in, for 60 s: both its links, both ways.
  std::this_thread::sleep_for(std::chrono::seconds(3));
  for (auto& [pair, link] : links) {
    if (pair.first == 2 || pair.second == 2) link->SetCut(true);
  }
  std::this_thread::sleep_for(std::chrono::seconds(60));
  for (auto& [pair, link] : links) link->SetCut(false);
  for (std::thread& t : runs) t.join();
  ASSERT_EQ(killed.term_signal, SIGKILL) << killed.output;
  for (int x = 0; x < kRobots; ++x) ASSERT_EQ(results[x].exit_code, 0) << team[x].name << ":\n" << results[x].output;
  EXPECT_GT(loss.Dropped(), 100u);

  std::vector<JsonValue> views;
  for (const Member& m : team) views.push_back(JsonValue::ParseFile(dir + "/" + m.name + "/team.json"));
  for (int x = 0; x < kRobots; ++x) {
    EXPECT_TRUE(views[x]["settled"].boolean()) << team[x].name;
    EXPECT_EQ(views[x]["exchange"]["decode_errors"].number(), 0) << team[x].name;
    EXPECT_EQ(views[x]["exchange"]["store_errors"].number(), 0) << team[x].name;
    EXPECT_EQ(views[x]["connected"].array().size(), 3u) << team[x].name;
    // Every origin's items, submaps included, are held once by everyone: as many as it holds itself.
    for (int y = 0; y < kRobots; ++y) {
      const JsonValue* held = RobotEntry(views[x], team[y].name);
      const JsonValue* own = RobotEntry(views[y], team[y].name);
      ASSERT_NE(held, nullptr);
      EXPECT_EQ(ItemCount(*held), ItemCount(*own)) << team[y].name << "'s items at " << team[x].name;
      EXPECT_EQ((*held)["items"]["submap"].number(), (*own)["items"]["submap"].number())
          << team[y].name << "'s submaps at " << team[x].name;
    }
  }
  for (int x = 0; x < kRobots; ++x) {
    const JsonValue& hexacopter = *RobotEntry(views[x], "hexacopter");
    EXPECT_EQ(hexacopter["items"]["run_start"].number(), 2) << team[x].name;  // both of its runs
    // The killed run is a run of its own in every graph once it sent estimates (it may not have).
    EXPECT_EQ(hexacopter["earlier_runs"].array().size(),
              (*RobotEntry(views[1], "hexacopter"))["earlier_runs"].array().size()) << team[x].name;
  }
  // The graphs agree on every robot's latest run, and on the killed run where all tied it in.
  std::vector<TeamView> graphs;
  for (const Member& m : team) {
    graphs.push_back(ReadView(dir, m.name, {"rover", "hexacopter", "rover2", "hexacopter.run0"}));
    EXPECT_GE(graphs.back().robots.size(), 3u) << m.name;
  }
  ExpectAgreement(graphs, 200);
  std::printf("faults: %llu packets dropped\n", static_cast<unsigned long long>(loss.Dropped()));
  for (int x = 0; x < kRobots; ++x) ExpectLanderFactorsOfEveryone(dir + "/" + team[x].name, team);
  ExpectSummaryRates(dir, team);
}

}  // namespace
}  // namespace cairn
