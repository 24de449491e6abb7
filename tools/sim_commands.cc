// cairn sim: writes a simulated multi-robot mission as EuRoC/ASL folders plus CAN logs.
// cairn bench sim: times the stereo renderer on the default world.

#include <time.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include "daemon/cairnd_config.h"
#include "sim/mission_simulator.h"
#include "sim/rover_can_layout.h"
#include "sim/world_file.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

constexpr const char* kSimUsage =
    "usage: cairn sim [--world WORLD.yaml] [--robots rover,hexacopter] [--duration SECONDS]\n"
    "                 [--seed N] [--rover-config FILE] [--image-scale S] [--motion-blur N]\n"
    "                 [--deploy-from-lander yes|no] --out DIR\n"
    "  --deploy-from-lander: every robot starts in front of one of the lander's tags (default no)\n"
    "  --motion-blur:  average N instants over each exposure (default 1: off)\n"
    "  --rover-config: cairnd profile whose 'can:' section gives the wheel CAN layout\n"
    "                  (default: the simulated rover's built-in layout, as in configs/rover.yaml)\n";

std::vector<std::string> SplitComma(const std::string& s) {
  std::vector<std::string> out;
  std::stringstream in(s);
  std::string item;
  while (std::getline(in, item, ',')) {
    if (!item.empty()) out.push_back(item);
  }
  return out;
}

bool ParseDouble(const std::string& s, double* out) {
  try {
    size_t used = 0;
    *out = std::stod(s, &used);
    return used == s.size();
  } catch (...) {
    return false;
  }
}

// A one-line progress bar on a terminal; silent otherwise.
class ProgressBar {
 public:
  ProgressBar() : tty_(isatty(STDERR_FILENO) != 0) {}
  void operator()(double fraction) {
    if (!tty_) return;
    const int percent = static_cast<int>(fraction * 100.0);
    if (percent == last_) return;
    last_ = percent;
    const int filled = percent * 40 / 100;
    std::fprintf(stderr, "\r[%s%s] %3d%%", std::string(static_cast<size_t>(filled), '#').c_str(),
                 std::string(static_cast<size_t>(40 - filled), ' ').c_str(), percent);
    if (percent == 100) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  }

 private:
  bool tty_;
  int last_ = -1;
};

// The built-in layout of the simulated rover, or the `can:` section of a given cairnd profile.
Expected<CanWheelOptions> LoadCanLayout(const std::string& profile) {
  if (profile.empty()) return sim::RoverCanLayout();
  auto options = LoadCairndOptions(profile, {});
  if (!options.ok()) return options.status();
  return options->can;
}

}  // namespace

namespace {
double CpuMs(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<double>(ts.tv_sec) * 1e3 + static_cast<double>(ts.tv_nsec) * 1e-6;
}
}  // namespace

double ThreadCpuMs() { return CpuMs(CLOCK_THREAD_CPUTIME_ID); }
double ProcessCpuMs() { return CpuMs(CLOCK_PROCESS_CPUTIME_ID); }

int RunSim(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kSimUsage);
  std::string world_path, out, rover_config;
  sim::MissionOptions mission;
  mission.robots = {"rover", "hexacopter"};
  int64_t seed = -1;
  // Every option takes a value.
  for (size_t i = 0; i < args.args.size(); i += 2) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    const std::string value = has_value ? args.args[i + 1] : "";
    double number = 0.0;
    if (a == "--world" && has_value) {
      world_path = value;
    } else if (a == "--out" && has_value) {
      out = value;
    } else if (a == "--rover-config" && has_value) {
      rover_config = value;
    } else if (a == "--robots" && has_value) {
      mission.robots = SplitComma(value);
    } else if (a == "--duration" && has_value && ParseDouble(value, &number)) {
      mission.duration = number;
    } else if (a == "--deploy-from-lander" && has_value && (value == "yes" || value == "no")) {
      mission.deploy_from_lander = value == "yes";
    } else if (a == "--motion-blur" && has_value && ParseDouble(value, &number) && number >= 1 && number <= 64) {
      mission.motion_blur_samples = static_cast<int>(number);
    } else if (a == "--image-scale" && has_value && ParseDouble(value, &number) && number > 0.01 && number <= 1.0) {
      mission.image_scale = number;
    } else if (a == "--seed" && has_value && ParseDouble(value, &number) && number >= 0 && number < 9e15 &&
               number == static_cast<double>(static_cast<int64_t>(number))) {
      seed = static_cast<int64_t>(number);
    } else {
      std::fprintf(stderr, "cairn sim: bad or incomplete argument '%s'\n%s", a.c_str(), kSimUsage);
      return 2;
    }
  }
  if (out.empty()) {
    std::fprintf(stderr, "cairn sim: --out DIR is required\n%s", kSimUsage);
    return 2;
  }
  sim::WorldOptions world;
  if (!world_path.empty()) {
    auto loaded = sim::LoadWorldFile(world_path);
    if (!loaded.ok()) {
      std::fprintf(stderr, "cairn sim: %s\n", loaded.status().message().c_str());
      return 1;
    }
    world = *loaded;
  }
  if (seed >= 0) world.seed = seed;
  auto can = LoadCanLayout(rover_config);
  if (!can.ok()) {
    std::fprintf(stderr, "cairn sim: %s\n", can.status().message().c_str());
    return 1;
  }
  mission.can = *can;
  mission.render_threads = 2;  // the right camera on a second thread: the same bytes, sooner
  const auto t0 = std::chrono::steady_clock::now();
  auto simulator = sim::MissionSimulator::Create(world, mission);
  if (!simulator.ok()) {
    std::fprintf(stderr, "cairn sim: %s\n", simulator.status().message().c_str());
    return 1;
  }
  std::error_code ec;
  std::filesystem::create_directories(out, ec);
  {
    std::ofstream w(out + "/world.yaml");
    w << sim::WorldFileText(world);
    if (!w) {
      std::fprintf(stderr, "cairn sim: %s/world.yaml: cannot write\n", out.c_str());
      return 1;
    }
  }
  ProgressBar bar;
  const Status st = (*simulator)->Write(out, [&](double f) { bar(f); });
  if (!st.ok()) {
    std::fprintf(stderr, "cairn sim: %s\n", st.message().c_str());
    return 1;
  }
  const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::printf("cairn sim: %zu robot(s), %.1f s mission, seed %lld -> %s (%.1f s wall)\n",
              mission.robots.size(), mission.duration, static_cast<long long>(world.seed), out.c_str(), secs);
  return 0;
}

constexpr const char* kBenchSimUsage =
    "usage: cairn bench sim [--repeats N]\n";

int RunBenchSim(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchSimUsage);
  int repeats = 15;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    double n = 0.0;
    if (a == "--repeats" && i + 1 < args.args.size() && ParseDouble(args.args[i + 1], &n) && n >= 1 && n <= 1000) {
      repeats = static_cast<int>(n);
      ++i;
    } else {
      std::fputs(kBenchSimUsage, stderr);
      return 2;
    }
  }
  using Clock = std::chrono::steady_clock;
  sim::WorldOptions world;
  sim::MissionOptions mission;
  mission.robots = {"rover", "hexacopter"};
  mission.duration = 60.0;
  const auto g0 = Clock::now();
  auto simulator = sim::MissionSimulator::Create(world, mission);
  if (!simulator.ok()) {
    std::fprintf(stderr, "cairn bench sim: %s\n", simulator.status().message().c_str());
    return 1;
  }
  const double gen_ms = std::chrono::duration<double, std::milli>(Clock::now() - g0).count();
  std::printf("world %.0f m x %.0f m at %.2f m: generated in %.0f ms, %.1f MB\n", world.size, world.size,
              world.resolution, gen_ms, static_cast<double>((*simulator)->terrain().memory_bytes()) / 1e6);
  std::vector<uint8_t> left, right;
  for (size_t r = 0; r < mission.robots.size(); ++r) {
    const auto& k = (*simulator)->robots()[r].stereo.left.intrinsics;
    std::vector<double> ms, cpu;
    for (int i = 0; i < repeats; ++i) {
      // Different instants along the path: the cost depends on the view.
      const double t = 4.0 * i;
      const auto s = Clock::now();
      const double c = ThreadCpuMs();
      (*simulator)->RenderStereo(r, t, static_cast<uint64_t>(i), &left, &right);
      cpu.push_back(ThreadCpuMs() - c);
      ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - s).count());
    }
    std::sort(ms.begin(), ms.end());
    std::sort(cpu.begin(), cpu.end());
    std::printf("%-11s %4dx%-4d stereo pair: median %.1f ms wall (min %.1f, max %.1f), median %.1f ms "
                "thread CPU; %d views, 1 thread, target 40 ms\n",
                mission.robots[r].c_str(), k.width, k.height, ms[ms.size() / 2], ms.front(), ms.back(),
                cpu[cpu.size() / 2], repeats);
  }
  return 0;
}

}  // namespace cairn::tools
