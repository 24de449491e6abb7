#pragma once
// Scores one image's obstacle classification against the simulator's true terrain, for the sim
// test and `cairn bench map`. Every cell the classifier observed is scored; a cell is a true
// obstacle when
//  - step: the true surface, averaged per cell as the classifier's 2.5-D grid averages its points
//    (thesis 5.1.1: "the mean height value of all points falling into it"), rises by more than
//    h_max between the observed cells of its window; or
//  - negative edge: the line of sight grazing the cell's true surface passes over a hidden stretch
//    (longer than the depth jump edge_jump) in which the true surface falls more steeply than
//    max_slope, a cliff or a boulder's back the camera cannot see (eq. 5.1).
// Cells whose true step lies within the stereo error of h_max (eq. 5.4 for the two extreme cells'
// true centres as seen from the camera, at least `min_ambiguity`) are not scored: the thesis'
// error-adaptive threshold h_max + delta_d leaves exactly that band undecided, in both directions.
// Likewise steep hidden stretches that exceed edge_jump by less than edge_jump_sigmas eq. 5.2c
// depth errors (a depth jump that size is not told from noise), and steep hidden stretches whose
// two visible ends, on the true surface, are joined by a slope of at most max_slope: eq. 5.1's
// minimal slope is all a line of sight tells about what it passes over, and such a view is equally
// that of a drivable slope (on the sim test's drive their steep parts fall by 2 to 16 cm, about h_max
// or less).
// (stereo_band = false: a fixed band of min_ambiguity only, to show what the stereo band leaves out.)

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

#include <Eigen/Geometry>

#include "mapping/obstacle_classifier.h"
#include "sim/terrain.h"
#include "stereo/stereo_error_model.h"

namespace cairn::testing {

struct ObstacleScore {
  int64_t tp = 0, fp = 0, fn = 0;
  int64_t unscored = 0;  // ambiguous cells
  int64_t unscored_hidden = 0;  // of those: steep hidden drops whose visible ends are not (eq. 5.1)
  int64_t fn_edge_only = 0;  // misses that are hidden drops without a true step
  double precision() const { return tp + fp ? static_cast<double>(tp) / static_cast<double>(tp + fp) : NAN; }
  double recall() const { return tp + fn ? static_cast<double>(tp) / static_cast<double>(tp + fn) : NAN; }
  void Add(const ObstacleScore& o) {
    tp += o.tp;
    fp += o.fp;
    fn += o.fn;
    unscored += o.unscored;
    unscored_hidden += o.unscored_hidden;
    fn_edge_only += o.fn_edge_only;
  }
};

// Largest downward slope (rise over run, > 0 falling away from the camera) of the true surface in
// the stretch hidden behind the top of (x, y) from the camera; 0 when the stretch is shorter than
// `min_hidden` along the line of sight. `*hidden_length`: that stretch along the line of sight;
// `*visible_slope`: eq. 5.1 between the top and where the line of sight meets the surface again
// (or ends at max_range), what the camera can tell about the stretch.
inline double HiddenDropSlope(const sim::Terrain& terrain, const Eigen::Vector3d& camera, double x, double y,
                              double min_hidden, double max_range, double* hidden_length, double* visible_slope) {
  // 2 cm above the surface, so the ray does not start inside it.
  const Eigen::Vector3d top(x, y, terrain.Height(x, y) + 0.02);
  const Eigen::Vector3d dir = (top - camera).normalized();
  const double reach = std::max(0.0, max_range - (top - camera).norm());
  const sim::TerrainHit hit = terrain.Raycast(top, dir, reach);
  const double hidden = hit.t < 0.0 ? reach : hit.t;
  *hidden_length = hidden;
  *visible_slope = ObstacleClassifier::MinimalSlope(Eigen::Vector3d(x, y, terrain.Height(x, y)), top + hidden * dir);
  if (hidden <= min_hidden) return 0.0;
  const Eigen::Vector2d h = dir.head<2>().normalized();
  const double run = hidden * dir.head<2>().norm();
  double steepest = 0.0;
  constexpr double kStep = 0.05;
  double prev = terrain.Height(x, y);
  for (double r = kStep; r <= run + 1e-9; r += kStep) {
    const double z = terrain.Height(x + r * h.x(), y + r * h.y());
    steepest = std::max(steepest, (prev - z) / kStep);
    prev = z;
  }
  return steepest;
}

// `result` from ObstacleClassifier::Classify on an image whose local frame is the terrain's,
// taken by a camera at T_world_cam; `model` the classifier's stereo error model.
inline ObstacleScore ScoreObstacles(const sim::Terrain& terrain, const ObstacleResult& result,
                                    const ObstacleOptions& options, const Eigen::Isometry3d& T_world_cam,
                                    const StereoErrorModel& model, double min_ambiguity = 0.03,
                                    bool stereo_band = true) {
  const double cell = options.cell_size;
  const auto index = [&](double v) { return static_cast<int64_t>(std::floor(v / cell)); };
  const auto pack = [](int64_t x, int64_t y) {
    return static_cast<uint64_t>(x + (int64_t{1} << 30)) << 32 | static_cast<uint64_t>(y + (int64_t{1} << 30));
  };
  // True mean height of each observed cell (5 x 5 samples over its area).
  std::unordered_map<uint64_t, double> mean;
  mean.reserve(2 * result.cells.size());
  for (const ObstacleCell& c : result.cells) {
    double sum = 0.0;
    for (int sy = -2; sy <= 2; ++sy) {
      for (int sx = -2; sx <= 2; ++sx) sum += terrain.Height(c.x + sx * cell / 5, c.y + sy * cell / 5);
    }
    mean[pack(index(c.x), index(c.y))] = sum / 25.0;
  }
  const Eigen::Isometry3d T_cam_world = T_world_cam.inverse();
  const Eigen::Vector3d camera = T_world_cam.translation();
  const int w = static_cast<int>(options.window_cells), wl = -(w - 1) / 2, wh = w / 2;
  ObstacleScore s;
  for (const ObstacleCell& c : result.cells) {
    const int64_t ix = index(c.x), iy = index(c.y);
    double mx = -1e9, mn = 1e9;
    int64_t ax = ix, ay = iy, bx = ix, by = iy;
    for (int dy = wl; dy <= wh; ++dy) {
      for (int dx = wl; dx <= wh; ++dx) {
        auto it = mean.find(pack(ix + dx, iy + dy));
        if (it == mean.end()) continue;
        if (it->second > mx) mx = it->second, ax = ix + dx, ay = iy + dy;
        if (it->second < mn) mn = it->second, bx = ix + dx, by = iy + dy;
      }
    }
    const double step = mx - mn;
    const auto centre = [&](int64_t gx, int64_t gy, double z) {
      return Eigen::Vector3d((static_cast<double>(gx) + 0.5) * cell, (static_cast<double>(gy) + 0.5) * cell, z);
    };
    const double band =
        stereo_band ? std::max(min_ambiguity, model.DistanceError(T_cam_world * centre(ax, ay, mx), T_cam_world * centre(bx, by, mn)))
                    : min_ambiguity;
    double hidden = 0.0, visible_slope = 0.0;
    const double slope = HiddenDropSlope(terrain, camera, c.x, c.y, options.edge_jump, options.edge_max_range,
                                         &hidden, &visible_slope);
    // A depth jump is told from noise only beyond edge_jump_sigmas eq. 5.2c errors of the depth.
    const double depth = (T_cam_world * Eigen::Vector3d(c.x, c.y, terrain.Height(c.x, c.y))).z();
    const double jump_noise = options.edge_jump_sigmas * model.DepthError(depth);
    const bool step_obstacle = step > options.max_step + band;
    const bool step_clear = step < options.max_step - band;
    const bool steep_hidden = slope > options.max_slope && hidden > options.edge_jump + jump_noise;
    const bool edge_obstacle = steep_hidden && visible_slope > options.max_slope;
    const bool edge_clear = slope <= options.max_slope || hidden <= options.edge_jump;
    bool truth;
    if (step_obstacle || edge_obstacle) {
      truth = true;
    } else if (step_clear && edge_clear) {
      truth = false;
    } else {
      ++s.unscored;
      s.unscored_hidden += steep_hidden && !step_obstacle;
      continue;
    }
    s.tp += c.obstacle && truth;
    s.fp += c.obstacle && !truth;
    s.fn += !c.obstacle && truth;
    s.fn_edge_only += !c.obstacle && truth && !step_obstacle;
  }
  return s;
}

}  // namespace cairn::testing
