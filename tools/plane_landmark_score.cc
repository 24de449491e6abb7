#include "tools/plane_landmark_score.h"

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
  Eigen::Vector3d normal, centroid;
  double chi2 = -1.0;  // none: not in that robot's graph
};

}  // namespace

Expected<PlaneLandmarkScore> ScorePlaneLandmarks(const std::vector<std::string>& dirs) {
  std::map<SubmapId, Eigen::Isometry3d> truth;
  std::map<std::pair<Face, Face>, Row> rows;
  for (const std::string& dir : dirs) {
    const std::string index = dir + "/submaps/index.csv";
    std::ifstream in(index);
    std::string line;
    std::getline(in, line);
    while (std::getline(in, line)) {
      const auto f = Fields(line);
      if (f.size() < 7 || f[3].empty()) continue;
      Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
      T.translation() = Eigen::Vector3d(std::stod(f[3]), std::stod(f[4]), std::stod(f[5]));
      T.linear() = Eigen::AngleAxisd(std::stod(f[6]), Eigen::Vector3d::UnitZ()).toRotationMatrix();
      truth[{f[0], std::stoull(f[1])}] = T;
    }
    const std::string csv = dir + "/planes.csv";
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
      r.normal = Eigen::Vector3d(std::stod(f[8]), std::stod(f[9]), std::stod(f[10]));
      r.centroid = Eigen::Vector3d(std::stod(f[12]), std::stod(f[13]), std::stod(f[14]));
      if (f.size() > 18 && !f[18].empty()) r.chi2 = std::stod(f[18]);
      auto [it, inserted] = rows.emplace(std::make_pair(r.face, r.landmark), r);
      // The largest residual any robot's graph ends with.
      if (!inserted) it->second.chi2 = std::max(it->second.chi2, r.chi2);
    }
  }
  PlaneLandmarkScore score;
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
    const double angle = std::acos(std::clamp(n1.dot(n2), -1.0, 1.0)) * 180.0 / std::numbers::pi;
    const double distance = std::abs(n1.dot(c2 - c1));
    if (angle > 5.0 || distance > 0.25) {
      ++score.wrong;
      if (r.chi2 >= 0.0 && r.chi2 <= 11.34) ++score.wrong_surviving;
    } else {
      score.max_angle_deg = std::max(score.max_angle_deg, angle);
      score.max_distance = std::max(score.max_distance, distance);
    }
  }
  return score;
}

}  // namespace cairn::tools
