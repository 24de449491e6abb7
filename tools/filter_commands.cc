// cairn bench filter [--samples N] [--delay S] [--switch-period S] [--wheel-rate HZ]
// [--nonholonomic] [--no-realtime]: wall time per IMU propagation, delayed relative-pose update, wheel update and
// frame switch of the local reference filter on a simulated run (200 Hz IMU, 20 Hz clones and
// relative poses, 20 Hz wheel odometry by default; the rover profile's CAN odometry runs at
// 100 Hz with the non-holonomic constraint: --wheel-rate 100 --nonholonomic).
// The measured loop runs as the daemon's filter thread does: SCHED_FIFO at the estimation
// executor's priority with the process memory locked (--no-realtime to skip); where the system
// refuses, it runs normally and the JSON says why. "machine_stalls" spins as long again in the
// same thread settings and reports the longest gap between two clock reads: the part of any
// maximum that the machine, not the filter, is responsible for.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <string>
#include <thread>
#include <vector>

#include "daemon/pipeline/executor.h"
#include "estimation/testing/filter_scenario.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

struct Timings {
  const char* name;
  std::vector<double> us;
};

void PrintStats(const Timings& t, bool last) {
  std::vector<double> v = t.us;
  std::sort(v.begin(), v.end());
  double mean = 0.0;
  for (double x : v) mean += x / static_cast<double>(v.empty() ? 1 : v.size());
  auto pct = [&](double p) {
    if (v.empty()) return 0.0;
    return v[std::min(v.size() - 1, static_cast<size_t>(p * static_cast<double>(v.size())))];
  };
  // Which step was the slowest, counted in order: the same step in every run is the filter's own
  // work (the bench is deterministic), a different one each time is the machine.
  const size_t max_at = static_cast<size_t>(std::max_element(t.us.begin(), t.us.end()) - t.us.begin());
  std::printf("    \"%s\": {\"count\": %zu, \"mean_us\": %.3f, \"median_us\": %.3f, \"p99_us\": %.3f, "
              "\"max_us\": %.3f, \"max_at\": %zu}%s\n",
              t.name, v.size(), mean, pct(0.5), pct(0.99), v.empty() ? 0.0 : v.back(), max_at, last ? "" : ",");
}

struct StallStats {
  double spin_s = 0.0;
  double max_gap_us = 0.0;
  long over_50us = 0;
  long over_200us = 0;
};

// Spins for `seconds` of busy time (pausing as the measured loop does) and records the gaps between
// consecutive clock reads.
StallStats MeasureStalls(double seconds) {
  using Clock = std::chrono::steady_clock;
  StallStats st;
  const auto budget = std::chrono::duration<double>(seconds);
  std::chrono::duration<double> busy{0.0};
  while (busy < budget) {
    const Clock::time_point start = Clock::now();
    Clock::time_point prev = start;
    while (prev - start < std::chrono::milliseconds(20) && busy + (prev - start) < budget) {
      const Clock::time_point now = Clock::now();
      const double gap_us = std::chrono::duration<double, std::micro>(now - prev).count();
      st.max_gap_us = std::max(st.max_gap_us, gap_us);
      st.over_50us += gap_us > 50.0 ? 1 : 0;
      st.over_200us += gap_us > 200.0 ? 1 : 0;
      prev = now;
    }
    busy += prev - start;
    std::this_thread::sleep_for(std::chrono::milliseconds(2));
  }
  st.spin_s = busy.count();
  return st;
}

}  // namespace

constexpr const char* kBenchFilterUsage =
    "usage: cairn bench filter [--samples N] [--delay S] [--switch-period S] [--wheel-rate HZ] "
    "[--nonholonomic] [--no-realtime]\n";

int RunBenchFilter(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchFilterUsage);
  long samples = 120000;
  double delay = 0.25, switch_period = 10.0, wheel_rate = 20.0;
  bool nonholonomic = false, realtime = true;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--samples" && has_value) {
      samples = std::strtol(args.args[++i], nullptr, 10);
    } else if (a == "--delay" && has_value) {
      delay = std::strtod(args.args[++i], nullptr);
    } else if (a == "--switch-period" && has_value) {
      switch_period = std::strtod(args.args[++i], nullptr);
    } else if (a == "--wheel-rate" && has_value) {
      wheel_rate = std::strtod(args.args[++i], nullptr);
    } else if (a == "--nonholonomic") {
      nonholonomic = true;
    } else if (a == "--no-realtime") {
      realtime = false;
    } else {
      std::fputs(kBenchFilterUsage, stderr);
      return 2;
    }
  }
  if (samples < 1000 || delay < 0.0 || delay > 0.45 || switch_period <= 0.0 || wheel_rate < 0.0 || wheel_rate > 200.0) {
    std::fprintf(stderr,
                 "cairn bench filter: need --samples >= 1000, 0 <= --delay <= 0.45, --switch-period > 0, "
                 "0 <= --wheel-rate <= 200\n");
    return 2;
  }
  testing::ScenarioOptions s;
  s.duration = static_cast<double>(samples) / 200.0;
  s.update_delay = delay;
  s.wheel_rate = wheel_rate;
  s.switch_period = switch_period;
  FilterOptions o;
  o.wheel_enabled = true;
  o.nonholonomic = nonholonomic;
  testing::FilterScenario scenario(s, o);
  std::vector<Timings> t = {{"imu_propagation", {}}, {"relative_pose_update", {}},
                            {"wheel_update", {}}, {"frame_switch", {}}};
  for (auto& x : t) x.us.reserve(static_cast<size_t>(samples));
  // Locked after everything is allocated, so the scenario and the timing buffers are resident.
  std::string lock_note;
  const bool locked = realtime && Executor::LockProcessMemory(&lock_note);
  ExecutorOptions eo;
  eo.realtime = realtime;
  eo.priority = 80;  // the estimation executor's priority in configs/
  Executor thread("bench-filter", eo);
  thread.Start([&](std::stop_token) {
    // The daemon's filter thread waits for its data; this loop would not, and a SCHED_FIFO thread
    // that stays busy for 950 ms of a second is stopped by the kernel's RT throttling for the
    // rest (a 50 ms "latency"). So it pauses 2 ms after every 20 ms of work, between steps.
    using Clock = std::chrono::steady_clock;
    Clock::time_point busy_since = Clock::now();
    while (scenario.Step([&](int kind, double seconds) { t[static_cast<size_t>(kind)].us.push_back(seconds * 1e6); })) {
      if (Clock::now() - busy_since > std::chrono::milliseconds(20)) {
        std::this_thread::sleep_for(std::chrono::milliseconds(2));
        busy_since = Clock::now();
      }
    }
  });
  thread.Join();
  // The machine's own stalls, for reading the maxima: the same thread settings spin for as long as
  // the filter was measured, reading the clock back to back. A gap between two reads is time in
  // which no code of this thread ran (preemption by the kernel or, on a VM, by the hypervisor), and
  // a filter step timed across it would have shown it too.
  double measured_s = 0.0;
  for (const auto& x : t) {
    for (double us : x.us) measured_s += us * 1e-6;
  }
  StallStats stalls;
  Executor spinner("bench-stalls", eo);
  spinner.Start([&](std::stop_token) { stalls = MeasureStalls(measured_s); });
  spinner.Join();
  std::string rt_note = thread.report().affinity_note;
  if (realtime && !locked) rt_note += (rt_note.empty() ? "" : "; ") + lock_note;
  const FilterCounters& c = scenario.filter().counters();
  std::printf("{\n  \"benchmark\": \"filter\",\n  \"imu_rate_hz\": 200, \"update_rate_hz\": 20, "
              "\"update_delay_s\": %.3f, \"max_clones\": %d, \"wheel_rate_hz\": %.1f, \"nonholonomic\": %s,\n",
              delay, kMaxClones, wheel_rate, nonholonomic ? "true" : "false");
  std::printf("  \"policy\": \"%s\", \"priority\": %d, \"memory_locked\": %s, \"realtime_note\": \"%s\",\n",
              thread.report().policy.c_str(), thread.report().priority, locked ? "true" : "false", rt_note.c_str());
  std::printf("  \"imu_samples\": %zu, \"updates_applied\": %lu, \"updates_rejected\": %lu, "
              "\"replays\": %lu, \"replayed_imu_samples\": %lu,\n",
              t[0].us.size(), static_cast<unsigned long>(c.updates_applied),
              static_cast<unsigned long>(c.updates_rejected), static_cast<unsigned long>(c.replays),
              static_cast<unsigned long>(c.replayed_imu_samples));
  std::printf("  \"timings\": {\n");
  for (size_t i = 0; i < t.size(); ++i) PrintStats(t[i], i + 1 == t.size());
  std::printf("  },\n  \"machine_stalls\": {\"spin_s\": %.3f, \"max_gap_us\": %.3f, \"gaps_over_50us\": %ld, "
              "\"gaps_over_200us\": %ld}\n}\n",
              stalls.spin_s, stalls.max_gap_us, stalls.over_50us, stalls.over_200us);
  return 0;
}

}  // namespace cairn::tools
