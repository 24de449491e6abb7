// cairn summary DIR...: one short block per cairnd output folder (what the run consumed, dropped
// and how it ended), read from its summary.json; simulated runs are also scored against the
// simulated world: the trajectory against the ground truth, the map against the true surfaces.

#include <cstdio>
#include <exception>
#include <string>
#include <vector>

#include <filesystem>
#include <optional>
#include <span>

#include "common/json_value.h"
#include "daemon/simulated_map_accuracy.h"
#include "estimation/eval/team_agreement.h"
#include "estimation/eval/team_evaluator.h"
#include "estimation/eval/trajectory.h"
#include "estimation/eval/trajectory_evaluator.h"
#include "tools/commands.h"
#include "tools/structure_landmark_score.h"

namespace cairn::tools {
namespace {

double CountOf(const JsonValue& streams, const char* name) {
  return streams.has(name) ? streams[name]["count"].number() : 0.0;
}

// Simulated runs carry their ground truth: score the estimate against it. Returns the alignment
// of the estimate's frame to the world when the evaluation succeeded.
// `file`'s accuracy against the simulator's (or the data set's) ground truth, labelled `what`.
std::optional<Eigen::Isometry3d> PrintAccuracy(const std::string& dir, const std::string& file, const char* what) {
  const std::string est_path = dir + "/" + file, gt_path = dir + "/ground_truth.tum";
  if (!std::filesystem::exists(est_path) || !std::filesystem::exists(gt_path)) return std::nullopt;
  auto est = TrajectoryIo::Read(est_path, TrajectoryFormat::kTum);
  auto gt = TrajectoryIo::Read(gt_path, TrajectoryFormat::kTum);
  if (!est.ok() || !gt.ok()) {
    std::printf("  %s: unreadable trajectory (%s)\n", what,
                (!est.ok() ? est.status() : gt.status()).message().c_str());
    return std::nullopt;
  }
  auto r = EvaluateTrajectory(*gt, *est, TrajectoryEvalOptions{});
  if (!r.ok()) {
    std::printf("  %s: %s\n", what, r.status().message().c_str());
    return std::nullopt;
  }
  std::printf("  %s: %.2f m path, ATE RMSE %.3f m, drift %.3f m / %.2f deg yaw", what, r->path_length, r->ate_rmse, r->drift_translation, r->drift_yaw_deg);
  for (const SegmentError& e : r->segments) {
    if (e.pairs > 0) {
      std::printf(", RPE@%.0fm %.2f %% %.3f deg/m", e.length, e.translation_percent, e.rotation_deg_per_m);
      break;
    }
  }
  std::printf("\n");
  return r->T_gt_est;
}

// The map's occupied voxels against the simulated world's true surfaces, in the world through the
// trajectory's alignment: the map's frame is trajectory.tum's (mapping_stage.cc).
void PrintMapAccuracy(const std::string& dir, const Eigen::Isometry3d& T_world_map) {
  if (!std::filesystem::exists(dir + "/map.bt")) return;
  const auto a = ScoreSimulatedMap(dir, T_world_map);
  if (!a.ok()) {
    std::printf("  map vs world: %s\n", a.status().ToString().c_str());
  } else if (a->occupied == 0) {
    std::printf("  map vs world: no occupied voxels\n");
  } else {
    std::printf("  map vs world: %lld occupied voxels, %.1f %% within one voxel (%.2f m) of a true surface\n",
                static_cast<long long>(a->occupied), 100.0 * a->fraction(), a->voxel);
  }
  if (a.ok() && !a->config_notes.empty()) {
    std::printf("  note: config.yaml is from another version: %zu keys missing or unknown, defaults used (first: %s)\n",
                a->config_notes.size(), a->config_notes.front().c_str());
  }
}

// The longest of summary.json's streams (the mission's data), or 0 when there is none.
double MissionSeconds(const JsonValue& streams) {
  double longest = 0.0;
  for (const auto& [name, stream] : streams.object()) {
    if (stream.has("duration_s")) longest = std::max(longest, stream["duration_s"].number());
  }
  return longest;
}

// team.json: the exchange per peer, and every robot's global trajectory as this robot's graph places
// it, scored with one alignment for the team against the ground truth in each robot's sibling
// output folder (the demo's out/<robot>/). Bytes sent are also given per second of the mission.
void PrintTeam(const std::string& dir, double mission_s) {
  const std::string path = dir + "/team.json";
  if (!std::filesystem::exists(path)) return;
  const JsonValue t = JsonValue::ParseFile(path);
  std::printf("  team: %s, exchange %.0f s%s\n", t["settled"].boolean() ? "settled" : "NOT settled",
              t["seconds"].number(), t["settled"].boolean() ? " (every teammate holds the same logs)" : "");
  double sent = 0.0;
  for (const JsonValue& p : t["peers"].array()) {
    std::printf("    link to %s: sent %.1f KB (%.2f KB/s), received %.1f KB (%.2f KB/s), items %.0f out / %.0f in, "
                "%.0f duplicates, %.0f resends, %.0f queued\n",
                p["name"].string().c_str(), p["sent_bytes"].number() / 1e3, p["sent_bytes_per_s"].number() / 1e3,
                p["received_bytes"].number() / 1e3, p["received_bytes_per_s"].number() / 1e3,
                p["items_sent"].number(), p["items_received"].number(), p["duplicates"].number(),
                p["resends"].number(), p["queued_items"].number());
    sent += p["sent_bytes"].number();
  }
  // Per second of the mission rather than of the exchange, which runs faster or slower than the
  // mission in a replay and lingers after it.
  if (mission_s > 0.0 && !t["peers"].array().empty()) {
    std::printf(
        "    sent per second of the %.0f s mission: %.2f KB/s per link (mean over %zu), %.2f KB/s over all "
        "links\n",
        mission_s, sent / 1e3 / mission_s / static_cast<double>(t["peers"].array().size()),
        t["peers"].array().size(), sent / 1e3 / mission_s);
  }
  std::vector<TeamTrajectory> team;
  std::string not_connected;
  const std::filesystem::path parent = std::filesystem::path(dir).parent_path();
  for (const JsonValue& r : t["robots"].array()) {
    const std::string name = r["name"].string();
    std::string items;
    for (const auto& [kind, n] : r["items"].object()) items += (items.empty() ? "" : ", ") + std::to_string(static_cast<long long>(n.number())) + " " + kind;
    std::printf("    robot %s (%s): %s; %s\n", name.c_str(), r["letter"].string().c_str(),
                r["connected"].boolean() ? "connected" : "not connected", items.empty() ? "no items" : items.c_str());
    if (!r["connected"].boolean()) {
      not_connected += " " + name;
      continue;
    }
    const std::string est = dir + "/global_trajectory_" + name + ".tum";
    const std::string gt = (parent / name / "ground_truth.tum").string();
    if (!std::filesystem::exists(est) || !std::filesystem::exists(gt)) continue;
    auto e = TrajectoryIo::Read(est, TrajectoryFormat::kTum);
    auto g = TrajectoryIo::Read(gt, TrajectoryFormat::kTum);
    if (e.ok() && g.ok()) team.push_back(TeamTrajectory{name, *g, *e});
  }
  if (team.empty()) return;
  auto r = EvaluateTeam(team, TrajectoryEvalOptions{});
  if (!r.ok()) {
    std::printf("    team accuracy: %s\n", r.status().message().c_str());
    return;
  }
  for (const auto& [name, e] : r->robots) {
    std::printf("    team accuracy (one alignment for %zu robots): %s %.2f m path, ATE RMSE %.3f m (%.2f %% of the path)\n",
                team.size(), name.c_str(), e.path_length, e.ate_rmse,
                e.path_length > 0.0 ? 100.0 * e.ate_rmse / e.path_length : 0.0);
  }
}

// The team as each robot's graph places it (team.json's connected robots and their
// global_trajectory_<robot>.tum), or nothing for a folder that is not a team member's.
std::optional<TeamView> ReadTeamView(const std::string& dir) {
  const std::string path = dir + "/team.json";
  if (!std::filesystem::exists(path)) return std::nullopt;
  const JsonValue t = JsonValue::ParseFile(path);
  TeamView view;
  view.viewer = std::filesystem::path(dir).filename().string();
  for (const JsonValue& r : t["robots"].array()) {
    if (!r["connected"].boolean()) continue;
    const std::string name = r["name"].string();
    auto e = TrajectoryIo::Read(dir + "/global_trajectory_" + name + ".tum", TrajectoryFormat::kTum);
    if (e.ok()) view.robots.emplace_back(name, *e);
  }
  return view;
}

// Whether the team members' graphs agree where they place every robot they all connect.
void PrintAgreement(const std::vector<TeamView>& views) {
  if (views.size() < 2) return;
  auto a = CompareTeamViews(views);
  if (!a.ok()) {
    std::printf("graph agreement: %s\n", a.status().message().c_str());
    return;
  }
  std::printf("graph agreement over %d robots' graphs (one rigid alignment per graph, %d poses): max %.2f mm, "
              "%.4f deg%s\n",
              a->views, a->compared_poses, 1e3 * a->max_position, a->max_rotation_deg,
              a->max_position > 0.0 ? (" (" + a->worst_robot + " as " + a->worst_viewer + " places it)").c_str() : "");
}

}  // namespace

constexpr const char* kSummaryUsage =
    "usage: cairn summary OUT_DIR [OUT_DIR ...]\n";

namespace {

// Plane and line landmarks against the simulator's truth, over every robot's observations.
void PrintStructureLandmarks(std::span<char* const> dirs, StructureKind kind) {
  const bool lines = kind == StructureKind::kLine;
  const char* what = lines ? "line landmarks" : "plane landmarks";
  bool any = false;
  for (const char* d : dirs)
    any = any || std::filesystem::exists(std::string(d) + (lines ? "/lines.csv" : "/planes.csv"));
  if (!any) return;
  const auto score = ScoreStructureLandmarks(std::vector<std::string>(dirs.begin(), dirs.end()), kind);
  if (!score.ok()) {
    std::printf("%s: %s\n", what, score.status().message().c_str());
    return;
  }
  const StructureLandmarkScore& s = *score;
  std::printf(
      "%s: %d landmarks, %d observations; of %d scored against the truth, %d wrong (%d of them "
      "still inside the gate at the end); right ones within %.1f deg and %.3f m of their first %s\n",
      what, s.landmarks, s.observations, s.scored, s.wrong, s.wrong_surviving, s.max_angle_deg,
      s.max_distance, lines ? "edge" : "face");
}

}  // namespace

int RunSummary(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kSummaryUsage);
  if (args.args.empty()) {
    std::fputs(kSummaryUsage, stderr);
    return 2;
  }
  int rc = 0;
  std::vector<TeamView> views;
  for (const char* dir : args.args) {
    const std::string path = std::string(dir) + "/summary.json";
    try {
      const JsonValue s = JsonValue::ParseFile(path);
      const JsonValue& streams = s["streams"];
      double dropped = 0.0;
      for (const auto& [queue, n] : s["dropped"].object()) dropped += n.number();
      std::printf("%s: robot %s, %s, %s%s\n", dir, s["robot"].string().c_str(), s["mode"].string().c_str(),
                  s["stop_reason"].string().c_str(), s["complete"].boolean() ? "" : " (incomplete)");
      std::printf("  consumed: imu %.0f, stereo %.0f, wheel odometry %.0f; dropped %.0f; device faults %.0f\n",
                  CountOf(streams, "imu"), CountOf(streams, "stereo"), CountOf(streams, "wheel_odometry"),
                  dropped, s["faults"]["total"].number());
      if (s.has("estimation")) {
        const JsonValue& e = s["estimation"];
        std::printf("  estimation: %.0f camera frames, %.0f poses, VO failures %.0f, frame switches %.0f\n",
                    e["camera_frames"].number(), e["trajectory_poses"].number(), e["vo"]["failures"].number(),
                    e["frame_switches"]["count"].number());
      }
      if (s.has("mapping")) {
        const JsonValue& m = s["mapping"];
        const JsonValue& d = m["dense_stereo"];
        const bool both_ways = d.has("bidirectional") && d["bidirectional"].boolean();
        std::printf("  mapping: %.0f pairs matched on %s%s (passes: FPGA %.0f, CPU %.0f, FPGA failures %.0f), %.0f "
                    "images mapped, %.0f submaps (%.0f KB), map of %.0f points\n",
                    d["pairs"].number(), d["backend"].string().c_str(), both_ways ? " top-down and bottom-up" : "",
                    d["fpga_frames"].number(),
                    d["cpu_frames"].number(), d["fpga_failures"].number(), m["images_mapped"].number(),
                    m["submaps"]["finished"].number(), m["submaps"]["bytes"].number() / 1024.0,
                    m["map_points"].number());
      }
      if (s.has("graph")) {
        const JsonValue& g = s["graph"];
        std::printf("  graph: %.0f submap origins, %.0f robot poses, %.0f factors (%.0f rejected), %.0f unplaced, "
                    "chi2 %.3g\n",
                    g["submap_origins"].number(), g["robot_poses"].number(), g["factors"].number(),
                    g["rejected_factors"].number(), g["unplaced"].number(), g["chi2"].number());
      }
      if (s.has("matching")) {
        const JsonValue& m = s["matching"];
        std::printf(
            "  matching: %.0f submaps (%.0f suitable, %.0f for the grey-level search only), %.0f attempts, "
            "%.0f matched, %.0f in the graph",
            m["submaps"].number(), m["suitable"].number(),
            m.has("searchable") ? m["searchable"].number() : 0.0, m["attempts"].number(),
            m["matched"].number(), m["accepted"].number());
        if (m.has("pairs")) {
          const char* sep = "; pairs: ";
          for (const auto& [why, count] : m["pairs"].object()) {
            std::printf("%s%.0f %s", sep, count.number(), why.c_str());
            sep = ", ";
          }
        }
        std::printf("\n");
      }
      if (s.has("detection")) {
        const JsonValue& d = s["detection"];
        const auto count = [&](const char* key) {
          return d.has(key) ? d[key].number() : 0.0;
        };  // older runs lack some
        std::printf(
            "  detection: %.0f images scanned whole, %.0f in regions around tracked tags (%.0f of the tags "
            "found there), %.0f regions where the graph placed a carrier (%.0f tags found there), "
            "%.0f tags of teammates or landmarks (%.0f usable, %.0f refused); "
            "in the graph %.0f robot detections d (%.0f as IPPE's other minimum, %.0f refused against "
            "gravity), "
            "%.0f landmark observations o, %.0f pending, %.0f unplaced\n",
            d.has("full_scans") ? d["full_scans"].number() : d["images"].number(), count("region_scans"),
            count("tags_in_regions"), count("predicted_regions"), count("tags_in_predicted_regions"),
            d["tags"].number(), d["usable"].number(), d["refused"].number(),
            d["graph_detections"].number(), count("graph_flipped"), count("graph_against_gravity"),
            d["graph_landmark_observations"].number(), d["graph_pending"].number(),
            d["graph_unplaced"].number());
      }
      const std::optional<Eigen::Isometry3d> T_world_est = PrintAccuracy(dir, "trajectory.tum", "accuracy vs ground truth");
      if (std::filesystem::exists(std::string(dir) + "/global_trajectory.tum"))
        PrintAccuracy(dir, "global_trajectory.tum", "global (graph) vs ground truth");
      if (T_world_est && s["mode"].string() == "sim") PrintMapAccuracy(dir, *T_world_est);
      PrintTeam(dir, MissionSeconds(streams));
      if (auto view = ReadTeamView(dir)) views.push_back(std::move(*view));
    } catch (const std::exception& e) {
      std::fprintf(stderr, "cairn summary: %s: %s\n", path.c_str(), e.what());
      rc = 1;
    }
  }
  PrintAgreement(views);
  PrintStructureLandmarks(args.args, StructureKind::kPlane);
  PrintStructureLandmarks(args.args, StructureKind::kLine);
  return rc;
}

}  // namespace cairn::tools
