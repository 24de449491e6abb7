// cairn graph switch-nees: the graph's frame-switch factors against the simulator's truth.

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <map>
#include <numbers>
#include <string>
#include <utility>
#include <vector>

#include "common/json_value.h"
#include "estimation/graph/g2o_io.h"
#include "estimation/graph/pairwise_consistency.h"
#include "tools/commands.h"
#include "tools/frame_switch_consistency.h"
#include "tools/sample_median.h"
#include "tools/submap_truth.h"

namespace cairn::tools {
namespace {

constexpr const char* kSwitchNeesUsage =
    "usage: cairn graph switch-nees OUT_DIR\n"
    "  The frame-switch factors (one submap origin to the robot's next) of OUT_DIR/graph.g2o against\n"
    "  the true origins in submaps/index.csv of OUT_DIR and, for a team, of its teammates' folders\n"
    "  beside it (named as OUT_DIR/team.json names them): per factor the error and its NEES over\n"
    "  x, y, z and yaw under the factor's covariance (4 on average where consistent), then the\n"
    "  mean, the median and the share inside chi-square(4)'s 95 % bound per robot.\n";

// Letter of each robot whose truth is read, and its folder.
Status TeamFolders(const std::string& dir, std::vector<std::pair<char, std::string>>* out) {
  const std::filesystem::path team = std::filesystem::path(dir) / "team.json";
  if (!std::filesystem::exists(team)) {
    out->emplace_back('\0', dir);  // one robot: every origin in the graph is its own
    return Status::Ok();
  }
  try {
    const JsonValue t = JsonValue::ParseFile(team.string());
    const std::filesystem::path parent = std::filesystem::path(dir).parent_path();
    for (const JsonValue& r : t["robots"].array()) {
      const std::string letter = r["letter"].string();
      if (letter.size() != 1)
        return InvalidArgumentError(team.string() + ": a robot's letter is not one character");
      out->emplace_back(letter[0], (parent / r["name"].string()).string());
    }
  } catch (const std::exception& e) {
    return InvalidArgumentError(team.string() + ": " + e.what());
  }
  return Status::Ok();
}

}  // namespace

int RunGraphSwitchNees(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kSwitchNeesUsage);
  if (args.args.size() != 1 || args.args[0][0] == 0 || args.args[0][0] == '-') {
    std::fputs(kSwitchNeesUsage, stderr);
    return 2;
  }
  const std::string dir = args.args[0];
  Expected<PoseGraph> graph = ReadG2o(dir + "/graph.g2o");
  if (!graph.ok()) {
    std::fprintf(stderr, "cairn graph switch-nees: %s\n", graph.status().ToString().c_str());
    return 1;
  }
  std::vector<std::pair<char, std::string>> folders;
  if (Status s = TeamFolders(dir, &folders); !s.ok()) {
    std::fprintf(stderr, "cairn graph switch-nees: %s\n", s.ToString().c_str());
    return 1;
  }
  std::map<std::pair<char, uint64_t>, FourDofTransform> truth;
  for (const auto& [letter, folder] : folders) {
    std::vector<SubmapTruth> rows;
    if (Status s = ReadSubmapTruth(folder, &rows); !s.ok()) {
      std::fprintf(stderr, "cairn graph switch-nees: %s\n", s.ToString().c_str());
      return 1;
    }
    for (const SubmapTruth& r : rows) truth[{letter, r.id}] = r.T_world_submap;
  }
  const bool one_robot = folders.size() == 1 && folders[0].first == '\0';
  const std::vector<FrameSwitchError> errors =
      FrameSwitchErrors(*graph, [&](char robot, uint64_t index) -> std::optional<FourDofTransform> {
        const auto it = truth.find({one_robot ? '\0' : robot, index});
        if (it == truth.end()) return std::nullopt;
        return it->second;
      });
  if (errors.empty()) {
    std::fprintf(stderr, "cairn graph switch-nees: no frame switch of %s/graph.g2o has true origins\n",
                 dir.c_str());
    return 1;
  }
  std::map<char, std::vector<double>> by_robot, longer;
  for (const FrameSwitchError& e : errors) {
    std::printf(
        "  %c %3llu -> next: %5.1f m (%+.3f %% long), error %.4f m %.3f deg, sigma x %.4f m yaw %.3f deg, "
        "NEES %7.2f\n",
        e.robot, static_cast<unsigned long long>(e.from), e.distance, 100.0 * (e.scale - 1.0), e.error_xy,
        e.error_yaw * 180.0 / std::numbers::pi, e.sigma_x, e.sigma_yaw * 180.0 / std::numbers::pi, e.nees);
    for (const char r : {e.robot, '*'}) {
      by_robot[r].push_back(e.nees);
      longer[r].push_back(e.scale - 1.0);
    }
  }
  const double bound = ChiSquareQuantile(0.95, 4);
  for (const auto& [robot, nees] : by_robot) {
    double sum = 0.0;
    size_t inside = 0;
    for (double n : nees) {
      sum += n;
      inside += n <= bound ? 1 : 0;
    }
    const size_t k = nees.size();
    const double median = Median(nees);
    const std::vector<double>& l = longer[robot];
    const size_t shorter =
        static_cast<size_t>(std::count_if(l.begin(), l.end(), [](double x) { return x < 0.0; }));
    double mean_longer = 0.0;
    for (double x : l) mean_longer += x / static_cast<double>(l.size());
    std::printf(
        "%s %c: %zu switches, NEES mean %.2f, median %.2f (consistent: 4, 3.36), %.0f %% inside the 95 %% "
        "bound; distances %+.3f %% long on average, %zu shorter than the truth\n",
        robot == '*' ? "all" : "robot", robot, k, sum / static_cast<double>(k), median,
        100.0 * static_cast<double>(inside) / static_cast<double>(k), 100.0 * mean_longer, shorter);
  }
  return 0;
}

}  // namespace cairn::tools
