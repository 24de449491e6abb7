#include "estimation/eval/trajectory.h"

#include <cctype>
#include <cerrno>
#include <cinttypes>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <sstream>

namespace cairn {
namespace {

std::string Lower(std::string s) {
  for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return s;
}

// Splits on commas and/or whitespace.
std::vector<std::string> Fields(const std::string& line) {
  std::vector<std::string> out;
  std::string cur;
  for (char c : line) {
    if (c == ',' || c == ' ' || c == '\t' || c == '\r') {
      if (!cur.empty()) out.push_back(cur);
      cur.clear();
    } else {
      cur += c;
    }
  }
  if (!cur.empty()) out.push_back(cur);
  return out;
}

bool ParseDouble(const std::string& s, double* v) {
  char* end = nullptr;
  *v = std::strtod(s.c_str(), &end);
  return end == s.c_str() + s.size() && std::isfinite(*v);
}

bool ParseInt(const std::string& s, int64_t* v) {
  char* end = nullptr;
  errno = 0;
  *v = std::strtoll(s.c_str(), &end, 10);
  return end == s.c_str() + s.size() && errno == 0;
}

Expected<Eigen::Quaterniond> UnitQuaternion(double w, double x, double y, double z, const std::string& where) {
  const Eigen::Quaterniond q(w, x, y, z);
  if (std::abs(q.norm() - 1.0) > 1e-3) {
    return DataLossError(where + ": quaternion norm " + std::to_string(q.norm()) + " is not 1");
  }
  return q.normalized();
}

// Decimal seconds to integer nanoseconds without going through a double (which keeps only about
// 0.2 us at today's epoch times).
bool ParseSecondsExact(const std::string& s, Timestamp* t) {
  const size_t dot = s.find('.');
  int64_t sec = 0;
  if (!ParseInt(s.substr(0, dot), &sec) || sec < 0) return false;
  int64_t ns = 0;
  if (dot != std::string::npos) {
    const std::string frac = s.substr(dot + 1);
    if (frac.empty() || frac.size() > 9) return false;
    for (char c : frac) {
      if (c < '0' || c > '9') return false;
    }
    ns = std::stoll(frac);
    for (size_t i = frac.size(); i < 9; ++i) ns *= 10;
  }
  *t = Timestamp::FromNanoseconds(sec * 1000000000 + ns);
  return true;
}

Eigen::Quaterniond Canonical(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  if (q.w() < 0.0) q.coeffs() = -q.coeffs();
  return q;
}

}  // namespace

Expected<TrajectoryFormat> TrajectoryIo::FormatFromName(const std::string& name) {
  const std::string n = Lower(name);
  if (n == "tum") return TrajectoryFormat::kTum;
  if (n == "euroc" || n == "csv") return TrajectoryFormat::kEurocCsv;
  if (n == "kitti") return TrajectoryFormat::kKitti;
  return InvalidArgumentError("unknown trajectory format '" + name + "' (tum, euroc, kitti)");
}

Expected<TrajectoryFormat> TrajectoryIo::FormatFromPath(const std::string& path) {
  const std::string p = Lower(path);
  const auto ends = [&](const char* e) {
    const std::string s(e);
    return p.size() >= s.size() && p.compare(p.size() - s.size(), s.size(), s) == 0;
  };
  if (ends(".tum") || ends(".txt")) return TrajectoryFormat::kTum;
  if (ends(".csv")) return TrajectoryFormat::kEurocCsv;
  if (ends(".kitti")) return TrajectoryFormat::kKitti;
  return InvalidArgumentError(path + ": cannot tell the trajectory format from the name (.tum, .csv, .kitti)");
}

std::string TrajectoryIo::Format(const Trajectory& t, TrajectoryFormat format) {
  std::string out;
  char line[512];
  if (format == TrajectoryFormat::kEurocCsv) {
    out += "#timestamp [ns], p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], q_RS_z []\n";
  } else if (format == TrajectoryFormat::kTum) {
    if (!t.frame.empty()) out += "# frame: " + t.frame + "\n";
    out += "# timestamp tx ty tz qx qy qz qw\n";
  }
  for (const StampedPose& p : t.poses) {
    const Eigen::Vector3d x = p.T_frame_body.translation();
    const Eigen::Quaterniond q = Canonical(p.T_frame_body.linear());
    const Eigen::Matrix3d R = p.T_frame_body.linear();
    switch (format) {
      case TrajectoryFormat::kTum: {
        // Seconds with nanosecond resolution, printed from the integer so nothing is lost.
        const int64_t ns = p.time.nanoseconds();
        std::snprintf(line, sizeof(line), "%" PRId64 ".%09" PRId64 " %.9f %.9f %.9f %.12f %.12f %.12f %.12f\n",
                      ns / 1000000000, ns % 1000000000, x.x(), x.y(), x.z(), q.x(), q.y(), q.z(), q.w());
        break;
      }
      case TrajectoryFormat::kEurocCsv:
        std::snprintf(line, sizeof(line), "%" PRId64 ",%.9f,%.9f,%.9f,%.12f,%.12f,%.12f,%.12f\n",
                      p.time.nanoseconds(), x.x(), x.y(), x.z(), q.w(), q.x(), q.y(), q.z());
        break;
      case TrajectoryFormat::kKitti:
        std::snprintf(line, sizeof(line), "%.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e %.9e\n",
                      R(0, 0), R(0, 1), R(0, 2), x.x(), R(1, 0), R(1, 1), R(1, 2), x.y(), R(2, 0), R(2, 1),
                      R(2, 2), x.z());
        break;
    }
    out += line;
  }
  return out;
}

std::string TrajectoryIo::KittiTimes(const Trajectory& t) {
  std::string out;
  char line[64];
  for (const StampedPose& p : t.poses) {
    const int64_t ns = p.time.nanoseconds();
    std::snprintf(line, sizeof(line), "%" PRId64 ".%09" PRId64 "\n", ns / 1000000000, ns % 1000000000);
    out += line;
  }
  return out;
}

Expected<Trajectory> TrajectoryIo::Read(const std::string& path, TrajectoryFormat format,
                                        const std::string& times_path) {
  std::ifstream in(path);
  if (!in) return NotFoundError(path + ": cannot open");
  std::vector<Timestamp> times;
  if (format == TrajectoryFormat::kKitti && !times_path.empty()) {
    std::ifstream tin(times_path);
    if (!tin) return NotFoundError(times_path + ": cannot open");
    std::string l;
    int n = 0;
    while (std::getline(tin, l)) {
      ++n;
      const auto f = Fields(l);
      if (f.empty()) continue;
      Timestamp v;
      double d;
      if (f.size() != 1 || !ParseDouble(f[0], &d)) {
        return DataLossError(times_path + ":" + std::to_string(n) + ": expected one time in seconds");
      }
      if (!ParseSecondsExact(f[0], &v)) v = Timestamp::FromSeconds(d);
      times.push_back(v);
    }
  }
  Trajectory t;
  std::string line;
  int number = 0;
  while (std::getline(in, line)) {
    ++number;
    const std::string where = path + ":" + std::to_string(number);
    const auto f = Fields(line);
    if (f.empty() || f[0][0] == '#') continue;
    StampedPose p;
    double v[16];
    const auto numbers = [&](size_t first, size_t count) {
      for (size_t i = 0; i < count; ++i) {
        if (!ParseDouble(f[first + i], &v[i])) return false;
      }
      return true;
    };
    if (format == TrajectoryFormat::kTum) {
      if (f.size() != 8 || !numbers(0, 8)) return DataLossError(where + ": expected 8 numbers 't tx ty tz qx qy qz qw'");
      // Exact when the seconds are plain decimals (as written here); scientific notation falls back
      // to double precision.
      if (!ParseSecondsExact(f[0], &p.time)) p.time = Timestamp::FromSeconds(v[0]);
      auto q = UnitQuaternion(v[7], v[4], v[5], v[6], where);
      if (!q.ok()) return q.status();
      p.T_frame_body.linear() = q->toRotationMatrix();
      p.T_frame_body.translation() = Eigen::Vector3d(v[1], v[2], v[3]);
    } else if (format == TrajectoryFormat::kEurocCsv) {
      int64_t ns;
      if (f.size() < 8 || !ParseInt(f[0], &ns) || !numbers(1, 7)) {
        return DataLossError(where + ": expected 'ns, px, py, pz, qw, qx, qy, qz[, ...]'");
      }
      p.time = Timestamp::FromNanoseconds(ns);
      auto q = UnitQuaternion(v[3], v[4], v[5], v[6], where);
      if (!q.ok()) return q.status();
      p.T_frame_body.linear() = q->toRotationMatrix();
      p.T_frame_body.translation() = Eigen::Vector3d(v[0], v[1], v[2]);
    } else {
      if (f.size() != 12 || !numbers(0, 12)) return DataLossError(where + ": expected 12 numbers (3x4 row-major)");
      Eigen::Matrix3d R;
      R << v[0], v[1], v[2], v[4], v[5], v[6], v[8], v[9], v[10];
      if ((R * R.transpose() - Eigen::Matrix3d::Identity()).norm() > 1e-4 || R.determinant() < 0.0) {
        return DataLossError(where + ": rotation is not orthonormal");
      }
      p.T_frame_body.linear() = Eigen::Quaterniond(R).normalized().toRotationMatrix();
      p.T_frame_body.translation() = Eigen::Vector3d(v[3], v[7], v[11]);
      const size_t index = t.poses.size();
      if (!times.empty() && index >= times.size()) {
        return DataLossError(times_path + ": fewer times than poses in " + path);
      }
      p.time = times.empty() ? Timestamp::FromSeconds(static_cast<double>(index)) : times[index];
    }
    t.poses.push_back(p);
  }
  if (format == TrajectoryFormat::kKitti && !times.empty() && times.size() != t.poses.size()) {
    return DataLossError(times_path + ": " + std::to_string(times.size()) + " times for " +
                         std::to_string(t.poses.size()) + " poses in " + path);
  }
  return t;
}

}  // namespace cairn
