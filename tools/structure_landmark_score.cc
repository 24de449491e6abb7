#include "tools/structure_landmark_score.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <numbers>
#include <set>
#include <sstream>
#include <tuple>

#include <Eigen/Geometry>

#include "tools/submap_truth.h"

namespace cairn::tools {
namespace {

std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> f;
  std::stringstream s(line);
  std::string item;
  while (std::getline(s, item, ',')) f.push_back(item);
  return f;
}

using SubmapId = std::pair<std::string, unsigned long long>;  // robot, submap of its current run
using Face = std::tuple<std::string, unsigned long long, unsigned>;

struct Row {
  Face face, landmark;
  Eigen::Vector3d normal, centroid;  // a line's direction and middle
  double chi2 = -1.0;  // none: not in that robot's graph
};

}  // namespace

Expected<StructureLandmarkScore> ScoreStructureLandmarks(const std::vector<std::string>& dirs,
                                                         StructureKind kind) {
  const bool lines = kind == StructureKind::kLine;
  std::map<SubmapId, Eigen::Isometry3d> truth;
  std::map<std::pair<Face, Face>, Row> rows;
  for (const std::string& dir : dirs) {
    std::vector<SubmapTruth> origins;
    const Status read = ReadSubmapTruth(dir, &origins);
    if (!read.ok() && read.code() != StatusCode::kNotFound) return read;  // no index: nothing scored
    for (const SubmapTruth& t : origins) truth[{t.robot, t.id}] = t.T_world_submap.ToIsometry();
    std::string line;
    const std::string csv = dir + (lines ? "/lines.csv" : "/planes.csv");
    if (!std::filesystem::exists(csv)) continue;
    std::ifstream p(csv);
    std::getline(p, line);
    int n = 1;
    while (std::getline(p, line)) {
      ++n;
      const auto f = Fields(line);
      if (f.size() < 18) return InvalidArgumentError(csv + ":" + std::to_string(n) + ": too few fields");
      // Earlier runs' faces (run > 0) have no truth in index.csv.
      if (f[1] != "0" || f[5] != "0") continue;
      Row r;
      r.face = {f[0], std::stoull(f[2]), static_cast<unsigned>(std::stoul(f[3]))};
      r.landmark = {f[4], std::stoull(f[6]), static_cast<unsigned>(std::stoul(f[7]))};
      // planes.csv: normal 8-10, offset 11, centroid 12-14; lines.csv: middle 8-10, direction 11-13.
      const size_t n0 = lines ? 11 : 8, c0 = lines ? 8 : 12;
      r.normal = Eigen::Vector3d(std::stod(f[n0]), std::stod(f[n0 + 1]), std::stod(f[n0 + 2]));
      r.centroid = Eigen::Vector3d(std::stod(f[c0]), std::stod(f[c0 + 1]), std::stod(f[c0 + 2]));
      if (f.size() > 18 && !f[18].empty()) r.chi2 = std::stod(f[18]);
      auto [it, inserted] = rows.emplace(std::make_pair(r.face, r.landmark), r);
      // The largest residual any robot's graph ends with.
      if (!inserted) it->second.chi2 = std::max(it->second.chi2, r.chi2);
    }
  }
  StructureLandmarkScore score;
  std::set<Face> landmarks;
  for (const auto& [key, r] : rows) landmarks.insert(r.landmark);
  score.landmarks = static_cast<int>(landmarks.size());
  for (const auto& [key, r] : rows) {
    ++score.observations;
    if (r.face == r.landmark) continue;  // the first face itself
    const auto first = rows.find({r.landmark, r.landmark});
    const auto t_obs = truth.find({std::get<0>(r.face), std::get<1>(r.face)});
    const auto t_first = truth.find({std::get<0>(r.landmark), std::get<1>(r.landmark)});
    if (first == rows.end() || t_obs == truth.end() || t_first == truth.end()) continue;
    ++score.scored;
    const Eigen::Vector3d n1 = t_first->second.linear() * first->second.normal;
    const Eigen::Vector3d c1 = t_first->second * first->second.centroid;
    const Eigen::Vector3d n2 = t_obs->second.linear() * r.normal;
    const Eigen::Vector3d c2 = t_obs->second * r.centroid;
    // An edge has no orientation; a face's normal has.
    const double cosine = lines ? std::abs(n1.dot(n2)) : n1.dot(n2);
    const double angle = std::acos(std::clamp(cosine, -1.0, 1.0)) * 180.0 / std::numbers::pi;
    const double distance = lines ? (c2 - c1 - (c2 - c1).dot(n1) * n1).norm() : std::abs(n1.dot(c2 - c1));
    if (angle > 5.0 || distance > 0.25) {
      ++score.wrong;
      if (r.chi2 >= 0.0 && r.chi2 <= (lines ? 13.28 : 11.34)) ++score.wrong_surviving;
    } else {
      score.max_angle_deg = std::max(score.max_angle_deg, angle);
      score.max_distance = std::max(score.max_distance, distance);
    }
  }
  return score;
}

}  // namespace cairn::tools
