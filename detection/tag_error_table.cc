#include "detection/tag_error_table.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <fstream>
#include <numbers>
#include <sstream>
#include <utility>

#include "common/angles.h"

namespace cairn {
namespace {

constexpr const char* kMagic = "cairn-tag-error-table";

std::string Where(const std::string& source, int line) { return source + ":" + std::to_string(line); }

}  // namespace

TagErrorTable::TagErrorTable(std::string camera, int width, int height, double fx, double fy, double tag_size,
                             double first_distance, double last_distance, int distances, double first_angle,
                             double last_angle, int angles)
    : camera_(std::move(camera)),
      width_(width),
      height_(height),
      fx_(fx),
      fy_(fy),
      tag_size_(tag_size),
      d0_(first_distance),
      d1_(last_distance),
      a0_(first_angle),
      a1_(last_angle),
      nd_(distances),
      na_(angles),
      cells_(static_cast<size_t>(std::max(0, distances * angles))) {}

Expected<TagErrorTable> TagErrorTable::Load(const std::string& path) {
  std::ifstream in(path);
  if (!in) return NotFoundError("tag error table " + path + ": cannot be read");
  std::stringstream ss;
  ss << in.rdbuf();
  return Parse(ss.str(), path);
}

Expected<TagErrorTable> TagErrorTable::Parse(const std::string& text, const std::string& source) {
  TagErrorTable t;
  std::istringstream lines(text);
  std::string line;
  int number = 0;
  bool magic = false, camera = false, size = false, corner = false, decimate = false, distances = false, angles = false;
  size_t row = 0;
  int last_line = 0;
  while (std::getline(lines, line)) {
    ++number;
    if (const size_t hash = line.find('#'); hash != std::string::npos) line.resize(hash);
    std::istringstream words(line);
    std::string key;
    if (!(words >> key)) continue;
    last_line = number;
    const std::string at = Where(source, number);
    if (!magic) {
      int version = 0;
      if (key != kMagic || !(words >> version))
        return InvalidArgumentError(at + ": not a tag error table (expected '" + kMagic + " 2')");
      if (version == 1)
        return InvalidArgumentError(at + ": version 1 tables do not say which detector decimation they were built for; "
                                         "rebuild it with cairn detect build-lut");
      if (version != 2) return InvalidArgumentError(at + ": version " + std::to_string(version) + " is not known (2 is)");
      magic = true;
      continue;
    }
    const bool header_done = camera && size && corner && decimate && distances && angles;
    if (!header_done) {
      bool ok = true;
      if (key == "camera") {
        ok = static_cast<bool>(words >> t.camera_ >> t.width_ >> t.height_ >> t.fx_ >> t.fy_) && t.width_ > 0 &&
             t.height_ > 0 && t.fx_ > 0.0 && t.fy_ > 0.0;
        camera = true;
      } else if (key == "tag_size") {
        ok = static_cast<bool>(words >> t.tag_size_) && t.tag_size_ > 0.0;
        size = true;
      } else if (key == "corner_rms") {
        ok = static_cast<bool>(words >> t.corner_rms_) && t.corner_rms_ >= 0.0;
        corner = true;
      } else if (key == "decimate") {
        ok = static_cast<bool>(words >> t.decimate_) && t.decimate_ >= 1.0 && t.decimate_ <= 8.0;
        decimate = true;
      } else if (key == "distances") {
        ok = static_cast<bool>(words >> t.d0_ >> t.d1_ >> t.nd_) && t.d0_ > 0.0 && t.d1_ > t.d0_ && t.nd_ >= 2 &&
             t.nd_ <= 10000;
        distances = true;
      } else if (key == "angles") {
        double a0 = 0.0, a1 = 0.0;
        ok = static_cast<bool>(words >> a0 >> a1 >> t.na_) && a0 >= 0.0 && a1 > a0 && a1 < 90.0 && t.na_ >= 2 &&
             t.na_ <= 10000;
        t.a0_ = a0 * kDegree;
        t.a1_ = a1 * kDegree;
        angles = true;
      } else if (std::isdigit(static_cast<unsigned char>(key[0])) || key[0] == '.' || key[0] == '-') {
        std::string missing;
        for (const auto& [have, name] : {std::pair{camera, "camera"}, std::pair{size, "tag_size"},
                                         std::pair{corner, "corner_rms"}, std::pair{decimate, "decimate"},
                                         std::pair{distances, "distances"}, std::pair{angles, "angles"}}) {
          if (!have) missing += std::string(missing.empty() ? "" : ", ") + name;
        }
        return InvalidArgumentError(at + ": a row before the header is complete (missing: " + missing + ")");
      } else {
        return InvalidArgumentError(at + ": '" + key +
                                    "' is not a header key (camera, tag_size, corner_rms, decimate, distances, angles)");
      }
      if (!ok) return InvalidArgumentError(at + ": '" + key + "' has missing or out-of-range values");
      if (camera && size && corner && decimate && distances && angles)
        t.cells_.assign(static_cast<size_t>(t.nd_ * t.na_), TagErrorCell{});
      continue;
    }
    if (row >= t.cells_.size())
      return InvalidArgumentError(at + ": more rows than distances x angles (" + std::to_string(t.cells_.size()) + ")");
    std::istringstream values(line);
    double d = 0.0, a = 0.0;
    TagErrorCell c;
    bool ok = static_cast<bool>(values >> d >> a >> c.rendered >> c.detected);
    for (int k = 0; k < 6 && ok; ++k) ok = static_cast<bool>(values >> c.sigma[k]);
    std::string extra;
    if (!ok || (values >> extra)) return InvalidArgumentError(at + ": a row needs 10 numbers");
    const int i = static_cast<int>(row) / t.na_, j = static_cast<int>(row) % t.na_;
    if (std::abs(d - t.distance_at(i)) > 1e-3 * std::max(1.0, d) || std::abs(a * kDegree - t.angle_at(j)) > 1e-3)
      return InvalidArgumentError(at + ": row for distance " + std::to_string(d) + " m, angle " + std::to_string(a) +
                                  " deg is out of order (expected " + std::to_string(t.distance_at(i)) + ", " +
                                  std::to_string(t.angle_at(j) / kDegree) + ")");
    if (c.rendered < 0 || c.detected < 0 || c.detected > c.rendered)
      return InvalidArgumentError(at + ": counts must satisfy 0 <= detected <= rendered");
    for (int k = 0; k < 6; ++k) {
      if (!(std::isfinite(c.sigma[k]) && c.sigma[k] > 0.0))
        return InvalidArgumentError(at + ": sigma " + std::to_string(k) + " must be finite and > 0");
    }
    t.cells_[row++] = c;
  }
  if (!magic) return InvalidArgumentError(source + ": empty; not a tag error table");
  if (!(camera && size && corner && decimate && distances && angles))
    return InvalidArgumentError(source + ": the header needs camera, tag_size, corner_rms, decimate, distances and angles");
  if (row != t.cells_.size())
    return InvalidArgumentError(Where(source, last_line) + ": " + std::to_string(row) + " rows where distances x angles is " +
                                std::to_string(t.cells_.size()));
  return t;
}

std::string TagErrorTable::Serialize() const {
  std::string out;
  char buf[256];
  out += std::string(kMagic) + " 2\n";
  out += "# RMS pose error of a tag by distance and viewing angle (cairn detect build-lut)\n";
  std::snprintf(buf, sizeof buf, "camera %s %d %d %.6g %.6g\ntag_size %.6g\ncorner_rms %.4f\ndecimate %.6g\n", camera_.c_str(),
                width_, height_, fx_, fy_, tag_size_, corner_rms_, decimate_);
  out += buf;
  std::snprintf(buf, sizeof buf, "distances %.6g %.6g %d\nangles %.6g %.6g %d\n", d0_, d1_, nd_, a0_ / kDegree, a1_ / kDegree, na_);
  out += buf;
  out += "# distance_m angle_deg rendered detected sigma_x_m sigma_y_m sigma_z_m sigma_rx_rad sigma_ry_rad sigma_rz_rad\n";
  for (int i = 0; i < nd_; ++i) {
    for (int j = 0; j < na_; ++j) {
      const TagErrorCell& c = cell(i, j);
      std::snprintf(buf, sizeof buf, "%.4f %.3f %d %d %.4e %.4e %.4e %.4e %.4e %.4e\n", distance_at(i),
                    angle_at(j) / kDegree, c.rendered, c.detected, c.sigma[0], c.sigma[1], c.sigma[2], c.sigma[3],
                    c.sigma[4], c.sigma[5]);
      out += buf;
    }
  }
  return out;
}

Eigen::Matrix<double, 6, 1> TagErrorTable::Sigma(double distance, double view_angle, double tag_size) const {
  Eigen::Matrix<double, 6, 1> s = Eigen::Matrix<double, 6, 1>::Zero();
  if (cells_.empty() || !(tag_size > 0.0) || !std::isfinite(distance) || !std::isfinite(view_angle)) return s;
  const double scale = tag_size / tag_size_;
  const double d = std::max(distance, 0.0) / scale;  // the table tag's distance that looks the same
  const double fd = std::clamp((d - d0_) / Step(d0_, d1_, nd_), 0.0, nd_ - 1.0);
  const double fa = std::clamp((std::abs(view_angle) - a0_) / Step(a0_, a1_, na_), 0.0, na_ - 1.0);
  const int i = std::min(static_cast<int>(fd), nd_ - 2), j = std::min(static_cast<int>(fa), na_ - 2);
  const double u = fd - i, v = fa - j;
  s = (1 - u) * (1 - v) * cell(i, j).sigma + (1 - u) * v * cell(i, j + 1).sigma + u * (1 - v) * cell(i + 1, j).sigma +
      u * v * cell(i + 1, j + 1).sigma;
  if (d > d1_) {
    const double r = d / d1_;
    s.head<3>() *= r * r;
    s.tail<3>() *= r;
  }
  s.head<3>() *= scale;
  return s;
}

void TagErrorTable::FillAndSmooth() {
  if (cells_.empty()) return;
  // Along each distance: angles past the last detected one take its value; before the first, the first's.
  for (int i = 0; i < nd_; ++i) {
    int first = -1, last = -1;
    for (int j = 0; j < na_; ++j) {
      if (cell(i, j).detected > 0) {
        if (first < 0) first = j;
        last = j;
      }
    }
    if (first < 0) continue;
    for (int j = 0; j < first; ++j) cell(i, j).sigma = cell(i, first).sigma;
    for (int j = first + 1; j < na_; ++j) {
      if (cell(i, j).detected == 0) cell(i, j).sigma = cell(i, j <= last ? j - 1 : last).sigma;
    }
  }
  // Along each angle: distances without a value take the largest of the last 10 % with one.
  for (int j = 0; j < na_; ++j) {
    std::vector<int> with;
    for (int i = 0; i < nd_; ++i) {
      if (cell(i, j).sigma.maxCoeff() > 0.0) with.push_back(i);
    }
    if (with.empty()) continue;
    const size_t tail = std::max<size_t>(1, with.size() / 10);
    Eigen::Matrix<double, 6, 1> far = Eigen::Matrix<double, 6, 1>::Zero();
    for (size_t k = with.size() - tail; k < with.size(); ++k) far = far.cwiseMax(cell(with[k], j).sigma);
    for (int i = 0; i < nd_; ++i) {
      if (cell(i, j).sigma.maxCoeff() > 0.0) continue;
      cell(i, j).sigma = i > with.back() ? far : cell(with.front(), j).sigma;
    }
  }
  // 3 x 3 median per coordinate (edges use the cells that exist).
  std::vector<TagErrorCell> smoothed = cells_;
  for (int i = 0; i < nd_; ++i) {
    for (int j = 0; j < na_; ++j) {
      for (int k = 0; k < 6; ++k) {
        std::vector<double> around;
        for (int di = -1; di <= 1; ++di)
          for (int dj = -1; dj <= 1; ++dj) {
            const int ii = i + di, jj = j + dj;
            if (ii >= 0 && ii < nd_ && jj >= 0 && jj < na_) around.push_back(cell(ii, jj).sigma[k]);
          }
        std::nth_element(around.begin(), around.begin() + static_cast<long>(around.size() / 2), around.end());
        smoothed[static_cast<size_t>(i * na_ + j)].sigma[k] = around[around.size() / 2];
      }
    }
  }
  cells_ = std::move(smoothed);
}

}  // namespace cairn
