// cairn bench rt [--config FILE] [--replay PATH] [--seconds S] [--stress-cpus N] [--out DIR]
// [--cairnd PATH] [--set key=value ...]: cairnd's estimation thread on a real-time paced run while
// stress-ng keeps every core busy, with cyclictest (rt-tests) run at the same time under the
// estimation executor's policy, priority and CPUs. It prints the latency from an IMU sample's
// arrival to the filter's estimate at it (median, p99.9, max, samples later than 1 ms) beside
// cyclictest's wake-up latency: cyclictest's maximum is what the machine alone costs, so ours is
// judged against it. The run is the simulated mission of the config (--sim) unless --replay
// names a recording or an EuRoC folder.

#include <signal.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "common/json_value.h"
#include "common/json_writer.h"
#include "daemon/cairnd_config.h"
#include "tools/child_process.h"
#include "tools/commands.h"
#include "tools/cyclictest_result.h"

namespace cairn::tools {
namespace {

namespace fs = std::filesystem;

constexpr const char* kUsage =
    "usage: cairn bench rt [--config FILE] [--replay PATH] [--seconds S] [--stress-cpus N] [--out DIR] "
    "[--cairnd PATH] [--set key=value ...]\n";

struct BenchArgs {
  std::string config = "configs/rover.yaml";
  std::string replay;
  double seconds = 600.0;
  int stress_cpus = 0;  // stress-ng: 0 = one worker per online CPU
  std::string out = "out/bench-rt";
  std::string cairnd;
  std::vector<std::string> overrides;
};

struct DaemonLatency {
  bool found = false;
  double count = 0.0, p50_us = 0.0, p999_us = 0.0, max_us = 0.0, over_1ms = 0.0;
  bool realtime_granted = false;
  std::string note;
};

// cairnd next to this program: installed side by side, or in the build tree's daemon/ folder.
std::string FindCairnd() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  if (ec) return "cairnd";
  for (const fs::path& p : {self.parent_path() / "cairnd", self.parent_path().parent_path() / "daemon" / "cairnd"}) {
    if (ProgramAvailable(p.string())) return p.string();
  }
  return "cairnd";
}

bool ParseArgs(const CommandArgs& args, BenchArgs* b) {
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    if (i + 1 >= args.args.size()) return false;
    const std::string v = args.args[++i];
    char* end = nullptr;
    if (a == "--config") {
      b->config = v;
    } else if (a == "--replay") {
      b->replay = v;
    } else if (a == "--seconds") {
      b->seconds = std::strtod(v.c_str(), &end);
      if (*end != '\0' || !std::isfinite(b->seconds) || b->seconds < 10.0) return false;
    } else if (a == "--stress-cpus") {
      b->stress_cpus = static_cast<int>(std::strtol(v.c_str(), &end, 10));
      if (*end != '\0' || b->stress_cpus < 0) return false;
    } else if (a == "--out") {
      b->out = v;
    } else if (a == "--cairnd") {
      b->cairnd = v;
    } else if (a == "--set") {
      b->overrides.push_back(v);
    } else {
      return false;
    }
  }
  return true;
}

DaemonLatency ReadDaemonLatency(const std::string& diagnostics) {
  DaemonLatency d;
  const JsonValue root = JsonValue::ParseFile(diagnostics);
  for (const JsonValue& l : root["latency"].array()) {
    if (l["stage_input"].string() != "imu_to_estimate") continue;
    d.found = true;
    d.count = l["count"].number();
    d.p50_us = l["p50_s"].number() * 1e6;
    d.p999_us = l["p999_s"].number() * 1e6;
    d.max_us = l["max_s"].number() * 1e6;
    d.over_1ms = l["over_1ms"].number();
  }
  for (const JsonValue& e : root["executors"].array()) {
    if (e["name"].string() != "estimation") continue;
    d.realtime_granted = e["realtime_granted"].boolean();
    if (e.has("note")) d.note = e["note"].string();
  }
  return d;
}

double Tenth(double us) { return std::round(us * 10.0) / 10.0; }

// Sleeps until `child` exits or `seconds` pass; true if it exited.
bool WaitFor(ChildProcess& child, double seconds) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
  while (std::chrono::steady_clock::now() < until) {
    if (!child.Running()) return true;
    std::this_thread::sleep_for(std::chrono::milliseconds(200));
  }
  return !child.Running();
}

}  // namespace

int RunBenchRt(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kUsage);
  BenchArgs b;
  if (!ParseArgs(args, &b)) {
    std::fprintf(stderr, "%s  --seconds >= 10 (default 600), --stress-cpus >= 0 (0: every CPU)\n", kUsage);
    return 2;
  }
  auto options = LoadCairndOptions(b.config, b.overrides);
  if (!options.ok()) {
    std::fprintf(stderr, "cairn bench rt: %s\n", options.status().message().c_str());
    return 1;
  }
  const ExecutorOptions& est = options->executors.estimation;
  if (b.cairnd.empty()) b.cairnd = FindCairnd();
  for (const std::string& program : {std::string("stress-ng"), std::string("cyclictest"), b.cairnd}) {
    if (!ProgramAvailable(program)) {
      std::fprintf(stderr, "cairn bench rt: %s not found (stress-ng and cyclictest: Debian packages stress-ng, rt-tests)\n",
                   program.c_str());
      return 1;
    }
  }
  // Only what this command writes is replaced: --out may name a folder that holds other things,
  // and cairnd keeps its own earlier outputs in OUT/cairnd/earlier-runs.
  std::error_code ec;
  fs::create_directories(b.out, ec);
  if (ec) {
    std::fprintf(stderr, "cairn bench rt: cannot create %s: %s\n", b.out.c_str(), ec.message().c_str());
    return 1;
  }
  for (const char* own : {"cyclictest.json", "cyclictest.log", "stress-ng.log", "cairnd.log", "bench_rt.json"}) {
    fs::remove(fs::path(b.out) / own, ec);
  }
  const std::string secs = std::to_string(static_cast<long>(std::lround(b.seconds)));
  // The machine's own latency, measured the way our thread is scheduled: same policy, priority
  // and CPUs (only those that exist, as the executor does).
  std::vector<std::string> ct = {"cyclictest", "-m", "-q", "-t1", "-i", "1000", "-h", "20000",
                                 "-D", secs + "s", "--json=" + b.out + "/cyclictest.json"};
  if (est.realtime) {
    ct.insert(ct.end(), {"--policy=fifo", "-p", std::to_string(est.priority)});
  } else {
    ct.insert(ct.end(), {"--policy=other", "-p", "0"});
  }
  std::string cpus;
  const long online = sysconf(_SC_NPROCESSORS_ONLN);
  for (double c : est.cpus) {
    if (static_cast<long>(c) < online) cpus += (cpus.empty() ? "" : ",") + std::to_string(static_cast<int>(c));
  }
  if (!cpus.empty()) ct.push_back("-a" + cpus);

  std::vector<std::string> daemon = {b.cairnd, "--config", b.config};
  if (b.replay.empty()) {
    daemon.insert(daemon.end(), {"--sim", "--set", "sim.duration=" + secs});
  } else {
    daemon.insert(daemon.end(), {"--replay", b.replay});
  }
  for (const char* kv : {"replay.pacing=realtime", "replay.deterministic=false", "live.enabled=false",
                         "recording.enabled=false", "team.enabled=false"}) {
    daemon.insert(daemon.end(), {"--set", kv});
  }
  for (const std::string& kv : b.overrides) daemon.insert(daemon.end(), {"--set", kv});
  daemon.insert(daemon.end(), {"--out", b.out + "/cairnd", "--log-level", "warn"});

  ChildProcess stress, cyclictest, cairnd;
  Status s = stress.Start({"stress-ng", "--cpu", std::to_string(b.stress_cpus), "--timeout",
                           std::to_string(static_cast<long>(b.seconds) + 120) + "s", "--metrics-brief"},
                          b.out + "/stress-ng.log");
  if (s.ok()) s = cyclictest.Start(ct, b.out + "/cyclictest.log");
  if (s.ok()) s = cairnd.Start(daemon, b.out + "/cairnd.log");
  if (!s.ok()) {
    std::fprintf(stderr, "cairn bench rt: %s\n", s.message().c_str());
    return 1;
  }
  std::fprintf(stderr, "cairn bench rt: %s s under stress-ng (%s CPUs) beside cyclictest; logs in %s\n", secs.c_str(),
               b.stress_cpus == 0 ? "all" : std::to_string(b.stress_cpus).c_str(), b.out.c_str());
  // The mission ends by itself; a longer replay is stopped as a service would be.
  if (!WaitFor(cairnd, b.seconds + 60.0)) {
    cairnd.Signal(SIGTERM);
  }
  const int daemon_rc = cairnd.Wait();
  // cyclictest writes its result when its duration ends or on SIGINT.
  if (!WaitFor(cyclictest, 5.0)) cyclictest.Signal(SIGINT);
  const int ct_rc = cyclictest.Wait();
  stress.Signal(SIGTERM);
  stress.Wait();
  if (daemon_rc != 0) {
    std::fprintf(stderr, "cairn bench rt: cairnd exited with %d (see %s/cairnd.log)\n", daemon_rc, b.out.c_str());
    return 1;
  }
  const auto machine = CyclictestReader::Read(b.out + "/cyclictest.json");
  if (!machine.ok()) {
    std::fprintf(stderr, "cairn bench rt: cyclictest exited with %d: %s\n", ct_rc, machine.status().message().c_str());
    return 1;
  }
  DaemonLatency ours;
  try {
    ours = ReadDaemonLatency(b.out + "/cairnd/diagnostics.json");
  } catch (const std::exception& e) {
    std::fprintf(stderr, "cairn bench rt: %s/cairnd/diagnostics.json: %s\n", b.out.c_str(), e.what());
    return 1;
  }
  if (!ours.found || ours.count == 0.0) {
    std::fprintf(stderr, "cairn bench rt: cairnd measured no IMU sample to estimate (is estimation enabled?)\n");
    return 1;
  }
  const double excess = ours.max_us - machine->max_us;
  JsonWriter j;
  j.BeginObject();
  j.Field("seconds", b.seconds).Field("source", b.replay.empty() ? std::string("sim") : b.replay);
  j.Field("stress_cpus", b.stress_cpus).Field("policy", est.realtime ? "fifo" : "other");
  j.Field("priority", static_cast<long>(est.priority)).Field("cpus", cpus.empty() ? std::string("any") : cpus);
  j.Field("realtime_granted", ours.realtime_granted);
  j.Key("imu_to_estimate").BeginObject();
  j.Field("samples", ours.count).Field("median_us", Tenth(ours.p50_us)).Field("p999_us", Tenth(ours.p999_us));
  j.Field("max_us", Tenth(ours.max_us)).Field("over_1ms", ours.over_1ms);
  j.EndObject();
  j.Key("cyclictest").BeginObject();
  j.Field("cycles", machine->cycles).Field("median_us", machine->median_us).Field("p999_us", machine->p999_us);
  j.Field("max_us", machine->max_us).Field("over_1ms", machine->over_1ms);
  j.EndObject();
  j.Field("max_minus_cyclictest_max_us", Tenth(excess));
  j.Field("target_no_sample_over_1ms", ours.over_1ms == 0.0);
  j.Field("target_max_within_100us_of_cyclictest", excess <= 100.0);
  j.EndObject();
  const std::string json = j.str() + "\n";
  std::fputs(json.c_str(), stdout);
  if (FILE* f = std::fopen((b.out + "/bench_rt.json").c_str(), "w")) {
    std::fputs(json.c_str(), f);
    std::fclose(f);
  }
  if (!ours.note.empty()) std::fprintf(stderr, "cairn bench rt: estimation executor: %s\n", ours.note.c_str());
  return 0;
}

}  // namespace cairn::tools
