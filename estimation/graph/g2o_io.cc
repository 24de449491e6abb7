#include "estimation/graph/g2o_io.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <sstream>
#include <tuple>

namespace cairn {
namespace {

// Stiffness given to the lifted z, roll and pitch of planar data, relative to the largest
// in-plane information, so that the 3-D solve stays in the plane without bad conditioning.
constexpr double kLiftStiffness = 1.0;

template <size_t N>
bool ReadNumbers(std::istringstream& in, double (&out)[N]) {
  for (double& v : out) {
    if (!(in >> v) || !std::isfinite(v)) return false;
  }
  return true;
}

bool ReadId(std::istringstream& in, uint64_t& id) {
  std::string token;
  if (!(in >> token) || token.empty() || token[0] == '-') return false;
  size_t used = 0;
  try {
    id = std::stoull(token, &used);
  } catch (...) {
    return false;
  }
  return used == token.size();
}

Eigen::Quaterniond QuaternionFromXyzw(const double* v, bool* ok) {
  Eigen::Quaterniond q(v[3], v[0], v[1], v[2]);
  const double n = q.norm();
  *ok = std::abs(n - 1.0) < 1e-3;  // files carry ~6 digits; anything further off is corrupt
  q.normalize();
  return q;
}

Status LineError(const std::string& name, int line, const std::string& what) {
  return DataLossError(name + ":" + std::to_string(line) + ": " + what);
}

// The same measurement written by two robots' files, which carry ~6 significant digits and may
// differ in the last one.
bool SamePose(const Pose3& a, const Pose3& b) {
  return (a.t - b.t).norm() < 1e-5 * std::max(1.0, a.t.norm()) && a.q.angularDistance(b.q) < 1e-5;
}

}  // namespace

Status ParseG2o(const std::string& text, const std::string& name, PoseGraph& graph) {
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  // Edges already present (from another robot's file) are skipped when identical.
  std::multimap<std::pair<uint64_t, uint64_t>, size_t> existing;
  for (size_t k = 0; k < graph.edges().size(); ++k) {
    existing.emplace(std::make_pair(graph.edges()[k].from, graph.edges()[k].to), k);
  }
  while (std::getline(lines, line)) {
    ++number;
    std::istringstream in(line);
    std::string tag;
    if (!(in >> tag) || tag[0] == '#') continue;
    std::string rest;
    if (tag == "VERTEX_SE3:QUAT") {
      uint64_t id;
      double v[7];
      if (!ReadId(in, id) || !ReadNumbers(in, v)) {
        return LineError(name, number, "VERTEX_SE3:QUAT needs an id and x y z qx qy qz qw");
      }
      bool ok;
      Pose3 p{Eigen::Vector3d(v[0], v[1], v[2]), QuaternionFromXyzw(v + 3, &ok)};
      if (!ok) return LineError(name, number, "quaternion is not unit length");
      graph.SetVertex(id, p);
      graph.set_has_initial_estimate(true);
    } else if (tag == "VERTEX_SE2") {
      uint64_t id;
      double v[3];
      if (!ReadId(in, id) || !ReadNumbers(in, v)) {
        return LineError(name, number, "VERTEX_SE2 needs an id and x y theta");
      }
      Pose3 p{Eigen::Vector3d(v[0], v[1], 0.0),
              Eigen::Quaterniond(Eigen::AngleAxisd(v[2], Eigen::Vector3d::UnitZ()))};
      graph.SetVertex(id, p);
      graph.set_has_initial_estimate(true);
    } else if (tag == "EDGE_SE3:QUAT") {
      PoseGraphEdge e;
      double v[7], info[21];
      if (!ReadId(in, e.from) || !ReadId(in, e.to) || !ReadNumbers(in, v) || !ReadNumbers(in, info)) {
        return LineError(name, number,
                         "EDGE_SE3:QUAT needs two ids, x y z qx qy qz qw and 21 information values");
      }
      bool ok;
      e.T_from_to = {Eigen::Vector3d(v[0], v[1], v[2]), QuaternionFromXyzw(v + 3, &ok)};
      if (!ok) return LineError(name, number, "quaternion is not unit length");
      int k = 0;
      for (int r = 0; r < 6; ++r) {
        for (int c = r; c < 6; ++c) e.information(r, c) = e.information(c, r) = info[k++];
      }
      e.planar = false;
      if (e.information.llt().info() != Eigen::Success) {
        // Only the SE-Sync objective can use it: its isotropic precisions need the two blocks alone.
        if (e.information.topLeftCorner<3, 3>().llt().info() != Eigen::Success ||
            e.information.bottomRightCorner<3, 3>().llt().info() != Eigen::Success) {
          return LineError(
              name, number,
              "information matrix is not positive definite, nor are its translation and rotation blocks");
        }
        e.definite = false;
        if (graph.first_indefinite().empty()) graph.set_first_indefinite(name + ":" + std::to_string(number));
      }
      PoseGraph::SetIsotropicWeights(e);
      bool duplicate = false;
      auto range = existing.equal_range({e.from, e.to});
      for (auto it = range.first; it != range.second && !duplicate; ++it) {
        duplicate = SamePose(graph.edges()[it->second].T_from_to, e.T_from_to);
      }
      if (!duplicate) graph.AddEdge(e);
    } else if (tag == "EDGE_SE2") {
      PoseGraphEdge e;
      double v[3], info[6];
      if (!ReadId(in, e.from) || !ReadId(in, e.to) || !ReadNumbers(in, v) || !ReadNumbers(in, info)) {
        return LineError(name, number, "EDGE_SE2 needs two ids, x y theta and 6 information values");
      }
      e.T_from_to = {Eigen::Vector3d(v[0], v[1], 0.0),
                     Eigen::Quaterniond(Eigen::AngleAxisd(v[2], Eigen::Vector3d::UnitZ()))};
      // (x, y, theta) -> (tx, ty, rz); z, roll, pitch get a stiff diagonal.
      const int map[3] = {0, 1, 5};
      Eigen::Matrix3d I2;
      I2 << info[0], info[1], info[2], info[1], info[3], info[4], info[2], info[4], info[5];
      if (I2.llt().info() != Eigen::Success) {
        return LineError(name, number, "information matrix is not positive definite");
      }
      e.information.setZero();
      for (int r = 0; r < 3; ++r) {
        for (int c = 0; c < 3; ++c) e.information(map[r], map[c]) = I2(r, c);
      }
      const double stiff = kLiftStiffness * I2.diagonal().maxCoeff();
      e.information(2, 2) = e.information(3, 3) = e.information(4, 4) = stiff;
      e.planar = true;
      PoseGraph::SetIsotropicWeights(e);
      graph.AddEdge(e);
    } else if (tag == "FIX" || tag == "PARAMS_SE3OFFSET" || tag == "VERTEX_TRACKXYZ") {
      return LineError(name, number, "unsupported record " + tag);
    } else {
      return LineError(name, number, "unknown record '" + tag + "'");
    }
    if (in >> rest) return LineError(name, number, "unexpected trailing '" + rest + "'");
  }
  return Status::Ok();
}

Expected<PoseGraph> ReadG2o(const std::string& path) {
  namespace fs = std::filesystem;
  std::error_code ec;
  std::vector<std::string> files;
  if (fs::is_directory(path, ec)) {
    for (const auto& entry : fs::directory_iterator(path, ec)) {
      if (entry.path().extension() == ".g2o") files.push_back(entry.path().string());
    }
    std::sort(files.begin(), files.end());
    if (files.empty()) return NotFoundError("no *.g2o file in " + path);
  } else {
    files.push_back(path);
  }
  PoseGraph graph;
  for (const auto& f : files) {
    std::ifstream in(f);
    if (!in) return NotFoundError("cannot open " + f);
    std::stringstream buffer;
    buffer << in.rdbuf();
    CAIRN_RETURN_IF_ERROR(ParseG2o(buffer.str(), f, graph));
  }
  if (graph.edges().empty()) return DataLossError(path + ": no edges");
  return graph;
}

std::string FormatG2o(const PoseGraph& graph) {
  std::ostringstream out;
  out.precision(17);
  const bool planar = graph.planar();
  for (size_t i = 0; i < graph.num_vertices(); ++i) {
    const Pose3& p = graph.poses()[i];
    if (planar) {
      const double yaw = std::atan2(p.R()(1, 0), p.R()(0, 0));
      out << "VERTEX_SE2 " << graph.ids()[i] << ' ' << p.t.x() << ' ' << p.t.y() << ' ' << yaw << '\n';
    } else {
      out << "VERTEX_SE3:QUAT " << graph.ids()[i] << ' ' << p.t.x() << ' ' << p.t.y() << ' '
          << p.t.z() << ' ' << p.q.x() << ' ' << p.q.y() << ' ' << p.q.z() << ' ' << p.q.w() << '\n';
    }
  }
  for (const auto& e : graph.edges()) {
    const Pose3& m = e.T_from_to;
    if (planar) {
      const double yaw = std::atan2(m.R()(1, 0), m.R()(0, 0));
      const Matrix6d& I = e.information;
      out << "EDGE_SE2 " << e.from << ' ' << e.to << ' ' << m.t.x() << ' ' << m.t.y() << ' ' << yaw
          << ' ' << I(0, 0) << ' ' << I(0, 1) << ' ' << I(0, 5) << ' ' << I(1, 1) << ' ' << I(1, 5)
          << ' ' << I(5, 5) << '\n';
    } else {
      out << "EDGE_SE3:QUAT " << e.from << ' ' << e.to << ' ' << m.t.x() << ' ' << m.t.y() << ' '
          << m.t.z() << ' ' << m.q.x() << ' ' << m.q.y() << ' ' << m.q.z() << ' ' << m.q.w();
      for (int r = 0; r < 6; ++r) {
        for (int c = r; c < 6; ++c) out << ' ' << e.information(r, c);
      }
      out << '\n';
    }
  }
  return out.str();
}

Status WriteG2o(const std::string& path, const PoseGraph& graph) {
  std::ofstream out(path);
  if (!out) return IoError("cannot write " + path);
  out << FormatG2o(graph);
  if (!out) return IoError("write failed: " + path);
  return Status::Ok();
}

}  // namespace cairn
