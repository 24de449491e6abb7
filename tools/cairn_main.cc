// cairn: offline tools around the cairnd daemon (stereo, evaluation, benchmarks, graphs, ...).

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <string>
#include <string_view>
#include <vector>

#include "tools/cairn_command.h"
#include "tools/commands.h"

namespace cairn::tools {

bool WantsHelp(const CommandArgs& args) {
  for (const char* a : args.args) {
    if (std::string_view(a) == "-h" || std::string_view(a) == "--help") return true;
  }
  return false;
}

int PrintUsage(const char* usage) {
  std::fputs(usage, stdout);
  return 0;
}

bool ParseNumberList(const std::string& s, std::vector<double>* out) {
  out->clear();
  size_t start = 0;
  while (start <= s.size()) {
    const size_t comma = std::min(s.find(',', start), s.size());
    const std::string item = s.substr(start, comma - start);
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (item.empty() || *end != '\0' || !std::isfinite(v)) return false;
    out->push_back(v);
    start = comma + 1;
  }
  return !out->empty();
}

namespace {

constexpr auto kCommands = std::to_array<Command>({
    {"config check", "load a cairnd config (and --set overrides) and report every error", RunConfigCheck},
    {"config doc", "print every configuration key with its unit, range and default", RunConfigDoc},
    {"summary", "a short account of cairnd output folders (from their summary.json)", RunSummary},
    {"mcap info", "summarize MCAP recordings (also ones cut short by a crash)", RunMcapInfo},
    {"keys generate", "a robot's CURVE key pair for the team exchange (<name>.key 0600, <name>.pub)",
     RunKeysGenerate},
    {"trajectory convert", "convert trajectories between TUM, EuRoC CSV and KITTI", RunTrajectoryConvert},
    {"stereo", "dense disparity of a stereo pair (SGM), written as PFM", RunStereo},
    {"stereo-eval", "score a disparity PFM against Middlebury/KITTI ground truth (JSON)", RunStereoEval},
    {"bench stereo", "time our SGM against OpenCV StereoSGBM side by side", RunBenchStereo},
    {"bench fpga", "cosimulate one frame on the FPGA SGM core: cycles per pixel, clock, latency",
     RunBenchFpga},
    {"bench filter", "time the local reference filter (propagation, delayed updates, switches)",
     RunBenchFilter},
    {"bench rt", "cairnd's IMU-to-estimate latency under full CPU load, beside cyclictest's", RunBenchRt},
    {"graph solve", "batch-solve a g2o pose graph (file or multi-robot dir) and print costs", RunGraphSolve},
    {"graph replay", "feed a g2o graph vertex by vertex into the online SLAM graph, time each update",
     RunGraphReplay},
    {"graph inject", "add random false loop closures to a g2o graph (robustness tests)", RunGraphInject},
    {"graph switch-nees", "a run's frame-switch factors against the simulator's true origins (NEES)",
     RunGraphSwitchNees},
    {"bench graph", "online SLAM graph on thesis-sized multi-robot graphs: update and covariance times",
     RunBenchGraph},
    {"sim", "simulate a multi-robot mission into EuRoC/ASL folders and CAN logs", RunSim},
    {"bench sim", "time rendering a stereo pair of the simulator's default world", RunBenchSim},
    {"map", "submap files: info, export (PCD/PLY, .bt/.ot), compose", RunMap},
    {"bench map", "time local mapping (classification, submap integration, wire size, composition)",
     RunBenchMap},
    {"bench lines",
     "time line segment detection and stereo triangulation on rendered keyframes of a structured world",
     RunBenchLines},
    {"match", "match two submap files (4-DoF: keypoints, descriptors, RANSAC, ICP) and print T_a_b as JSON",
     RunMatch},
    {"bench match",
     "time submap matching on cairnd runs' submaps; recall and precision against the simulator",
     RunBenchMatch},
    {"bench landmarks", "time pairing submaps' straight edges into line landmarks on cairnd runs' submaps",
     RunBenchLandmarks},
    {"detect", "AprilTag 36h11 tags in a photo: corners, T_cam_tag and its covariance as JSON", RunDetect},
    {"detect build-lut", "the precomputed tag error table of one robot camera, from rendered tags",
     RunDetectBuildLut},
    {"detect check-lut",
     "NEES of each tag error model and recall on rendered tags a table was not built from",
     RunDetectCheckLut},
    {"bench detect", "time AprilTag detection on simulated rover frames: whole frame and region of interest",
     RunBenchDetect},
    {"eval", "trajectory accuracy vs ground truth (TUM/EuRoC): ATE, RPE, drift as JSON", RunEval},
    {"bench vo", "visual-odometry time per stereo frame on an EuRoC/ASL folder (no SGM)", RunBenchVo},
    {"bench vo-scale", "where the odometry gains or loses scale, stage by stage, on simulated pairs",
     RunBenchVoScale},
});

void PrintHelp() {
  std::printf("usage: cairn COMMAND [ARGS...]\n\ncommands:\n");
  for (const Command& c : kCommands) {
    std::printf("  %-16s %.*s\n", std::string(c.name).c_str(), static_cast<int>(c.summary.size()),
                c.summary.data());
  }
}

}  // namespace
}  // namespace cairn::tools

int main(int argc, char** argv) {
  using cairn::tools::kCommands;
  if (argc < 2 || std::string(argv[1]) == "help" || std::string(argv[1]) == "--help") {
    cairn::tools::PrintHelp();
    return argc < 2 ? 2 : 0;
  }
  // Two-word commands ("bench stereo") take precedence over one-word ones ("stereo").
  for (int words = 2; words >= 1; --words) {
    if (argc < 1 + words) continue;
    std::string name = argv[1];
    if (words == 2) name += std::string(" ") + argv[2];
    for (const auto& c : kCommands) {
      if (c.name == name) {
        cairn::tools::CommandArgs args{c.name, std::span<char* const>(argv + 1 + words,
                                                                    static_cast<size_t>(argc - 1 - words))};
        return c.run(args);
      }
    }
  }
  std::fprintf(stderr, "cairn: unknown command '%s' (see 'cairn help')\n", argv[1]);
  return 2;
}
