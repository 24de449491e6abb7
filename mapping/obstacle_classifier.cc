#include "mapping/obstacle_classifier.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "mapping/voxel_hash_map.h"  // VoxelKey::Floor

namespace cairn {

ObstacleClassifier::ObstacleClassifier(const ObstacleOptions& options, const StereoCamera& camera,
                                       const StereoErrorModel& model, double range)
    : options_(options), camera_(camera), model_(model) {
  n_ = 2 * static_cast<int>(std::ceil(range / options.cell_size)) + 2 * static_cast<int>(options.window_cells) + 2;
  const size_t cells = static_cast<size_t>(n_) * static_cast<size_t>(n_);
  sum_z_.assign(cells, 0.0f);
  count_.assign(cells, 0);
  edge_ratio_.assign(cells, 0.0f);
  cell_obstacle_.assign(cells, 0);
  touched_.reserve(cells);
  last_depth_.resize(static_cast<size_t>(camera.intrinsics.width));
  last_row_.resize(static_cast<size_t>(camera.intrinsics.width));
}

double ObstacleClassifier::MinimalSlope(const Eigen::Vector3d& p, const Eigen::Vector3d& q) {
  const double run = std::hypot(q.x() - p.x(), q.y() - p.y());
  if (run <= 0.0) return p.z() > q.z() ? std::numeric_limits<double>::infinity() : 0.0;
  return (p.z() - q.z()) / run;
}

// Row by row rather than column by column: the same comparisons of each pixel with the last valid
// one above it, in memory order.
void ObstacleClassifier::FindNegativeEdges(const DepthImage& image, const Eigen::Isometry3d& T_local_cam) {
  const PinholeRadTan& k = camera_.intrinsics;
  std::fill(last_row_.begin(), last_row_.end(), -1);
  edges_.clear();
  const float jump = static_cast<float>(options_.edge_jump);
  const int gap = static_cast<int>(options_.edge_max_gap_rows);
  const double far = options_.edge_max_range;
  const float sigmas = static_cast<float>(options_.edge_jump_sigmas);
  const float c = static_cast<float>(model_.DepthError(1.0));  // eq. 5.2c: c z^2
  const auto point = [&](int u, int v, double z) {
    return Eigen::Vector3d(T_local_cam * Eigen::Vector3d((u - k.cx) / k.fx * z, (v - k.cy) / k.fy * z, z));
  };
  for (int v = 0; v < image.height; ++v) {
    const float* row = image.depth.data() + static_cast<size_t>(v) * static_cast<size_t>(image.width);
    for (int u = 0; u < image.width; ++u) {
      const float z = row[u];
      if (std::isnan(z)) continue;
      const int above = last_row_[static_cast<size_t>(u)];
      const float upper = last_depth_[static_cast<size_t>(u)];
      last_row_[static_cast<size_t>(u)] = v;
      last_depth_[static_cast<size_t>(u)] = z;
      if (above < 0 || v - above - 1 > gap || !(upper - z > jump) || !std::isfinite(z)) continue;
      if (!(upper - z > jump + sigmas * c * z * z)) continue;
      const Eigen::Vector3d p = point(u, v, z);
      const Eigen::Vector3d q = point(u, above, std::min(static_cast<double>(upper), far));
      const double s = MinimalSlope(p, q);
      if (s > options_.max_slope) {
        edges_.push_back({static_cast<uint32_t>(v * image.width + u), static_cast<float>(s / options_.max_slope)});
      }
    }
  }
}

template <typename CentreCam>
double ObstacleClassifier::DecisivePairRatio(int gx, int gy, float zmin, float zmax, const CentreCam& centre_cam) {
  const int w = static_cast<int>(options_.window_cells);
  const int lo = -(w - 1) / 2, hi = w / 2;
  const float h_max = static_cast<float>(options_.max_step);
  const float tol = static_cast<float>(options_.step_tie_tolerance);
  // Of the near-extreme cells, only those more than h_max above the window's lowest can top a
  // step, and only those more than h_max below its highest can be its foot.
  tops_.clear();
  feet_.clear();
  for (int dy = lo; dy <= hi; ++dy) {
    for (int dx = lo; dx <= hi; ++dx) {
      const int q = (gy + dy) * n_ + gx + dx;
      const size_t qs = static_cast<size_t>(q);
      if (count_[qs] == 0) continue;
      const float h = sum_z_[qs];
      if (h >= zmax - tol && h - zmin > h_max) tops_.push_back({q, centre_cam(q)});
      if (h <= zmin + tol && zmax - h > h_max) feet_.push_back({q, centre_cam(q)});
    }
  }
  double best = 0.0;
  for (const WindowCell& t : tops_) {
    const float ht = sum_z_[static_cast<size_t>(t.cell)];
    for (const WindowCell& f : feet_) {
      const double rise = static_cast<double>(ht - sum_z_[static_cast<size_t>(f.cell)]);
      if (rise <= options_.max_step) continue;
      best = std::max(best, rise / (options_.max_step + model_.DistanceError(t.p_cam, f.p_cam)));
    }
  }
  return best;
}

Status ObstacleClassifier::Classify(const DepthImage& image, CameraPoints* pts, ObstacleResult* result) {
  result->Clear();
  if (image.width != camera_.intrinsics.width || image.height != camera_.intrinsics.height ||
      image.depth.size() != static_cast<size_t>(image.width) * static_cast<size_t>(image.height)) {
    return InvalidArgumentError("obstacle classification: depth image does not match the camera");
  }
  FindNegativeEdges(image, pts->T_local_cam);

  // Height grid centred on the camera, aligned with the local frame's axes.
  const double cell = options_.cell_size;
  const float inv = static_cast<float>(1.0 / cell);
  const Eigen::Vector3d cam = pts->T_local_cam.translation();
  const int ox = static_cast<int>(std::floor(cam.x() / cell)) - n_ / 2;
  const int oy = static_cast<int>(std::floor(cam.y() / cell)) - n_ / 2;
  const int margin = static_cast<int>(options_.window_cells);
  for (int32_t c : touched_) {
    sum_z_[static_cast<size_t>(c)] = 0.0f;
    count_[static_cast<size_t>(c)] = 0;
    edge_ratio_[static_cast<size_t>(c)] = 0.0f;
    cell_obstacle_[static_cast<size_t>(c)] = 0;
  }
  touched_.clear();
  const size_t np = pts->size();
  cell_of_point_.resize(np);
  // Raw pointers and local counters: the compiler cannot keep vector internals or result fields
  // in registers across the stores of this loop and the last one (uint8_t stores may alias
  // anything), and reloading them per point cost a fifth of the classification.
  const Eigen::Vector3f* p_local = pts->p_local.data();
  const uint32_t* pixel = pts->pixel.data();
  int32_t* cell_of_point = cell_of_point_.data();
  float* sum_z = sum_z_.data();
  int32_t* count = count_.data();
  float* edge_ratio = edge_ratio_.data();
  const Edge* edges = edges_.data();
  const size_t n_edges = edges_.size();
  const int n = n_;
  int64_t negative_edges = 0;
  size_t e = 0;
  for (size_t i = 0; i < np; ++i) {
    const Eigen::Vector3f& p = p_local[i];
    const int gx = VoxelKey::Floor(p.x() * inv) - ox;
    const int gy = VoxelKey::Floor(p.y() * inv) - oy;
    if (gx < margin || gy < margin || gx >= n - margin || gy >= n - margin) {
      cell_of_point[i] = -1;
      continue;
    }
    const int32_t c = gy * n + gx;
    cell_of_point[i] = c;
    const size_t cs = static_cast<size_t>(c);
    if (count[cs] == 0) touched_.push_back(c);
    sum_z[cs] += p.z();
    ++count[cs];
    // Points and edges are both in pixel order.
    while (e < n_edges && edges[e].pixel < pixel[i]) ++e;
    if (e < n_edges && edges[e].pixel == pixel[i]) {
      edge_ratio[cs] = std::max(edge_ratio[cs], edges[e].ratio);
      ++negative_edges;
    }
  }
  result->negative_edges = negative_edges;
  for (int32_t c : touched_) sum_z_[static_cast<size_t>(c)] /= static_cast<float>(count_[static_cast<size_t>(c)]);
  // One stereo point is no estimate of its cell's mean height: such cells lie where the view grazes
  // the surface or is cut off by an occlusion, and the lone point, from a sliver of the cell, then
  // decides the steps of its whole window. Cells holding a negative edge stay (the edge decides).
  const int32_t min_points = static_cast<int32_t>(options_.min_cell_points);
  if (min_points > 1) {
    size_t kept = 0;
    for (int32_t c : touched_) {
      const size_t cs = static_cast<size_t>(c);
      if (count_[cs] >= min_points || edge_ratio_[cs] > 1.0f) {
        touched_[kept++] = c;
      } else {
        sum_z_[cs] = 0.0f;
        count_[cs] = 0;
        edge_ratio_[cs] = 0.0f;
      }
    }
    touched_.resize(kept);
  }

  // Window of w cells around each observed cell: [-(w-1)/2, w/2] (even windows lean positive).
  const int w = static_cast<int>(options_.window_cells);
  const int lo = -(w - 1) / 2, hi = w / 2;
  const Eigen::Isometry3d T_cam_local = pts->T_local_cam.inverse();
  const double h_max = options_.max_step;
  // Centre of grid cell q at its mean height, in the camera frame (eq. 5.4 is in camera coordinates).
  const auto centre_cam = [&](int q) {
    return Eigen::Vector3d(T_cam_local * Eigen::Vector3d((ox + q % n_ + 0.5) * cell, (oy + q / n_ + 0.5) * cell,
                                                         sum_z_[static_cast<size_t>(q)]));
  };
  result->cells.reserve(touched_.size());
  for (int32_t c : touched_) {
    const int gx = c % n_, gy = c / n_;
    float zmax = -std::numeric_limits<float>::infinity(), zmin = std::numeric_limits<float>::infinity();
    int cmax = c, cmin = c;
    for (int dy = lo; dy <= hi; ++dy) {
      const int row = (gy + dy) * n_;
      for (int dx = lo; dx <= hi; ++dx) {
        const size_t q = static_cast<size_t>(row + gx + dx);
        if (count_[q] == 0) continue;
        const float h = sum_z_[q];
        if (h > zmax) { zmax = h; cmax = static_cast<int>(q); }
        if (h < zmin) { zmin = h; cmin = static_cast<int>(q); }
      }
    }
    const double h_diff = static_cast<double>(zmax - zmin);
    double threshold = h_max;
    if (options_.error_adaptive && cmax != cmin) {
      threshold += model_.DistanceError(centre_cam(cmax), centre_cam(cmin));
    }
    double step_ratio = h_diff / threshold;
    bool step_obstacle = h_diff > threshold;
    // Eq. 5.4 depends on the two cells' placement, not only on their heights: on a rock top or a
    // slope several cells are within noise of the highest, and which of them comes out highest is
    // chance, yet decides delta_d (by a factor of two on the simulated rocks). A step between
    // such near-extreme cells that exceeds h_max by more than its own delta_d is as certain.
    if (options_.error_adaptive && options_.step_tie_tolerance > 0.0 && !step_obstacle && h_diff > h_max) {
      const double pair_ratio = DecisivePairRatio(gx, gy, zmin, zmax, centre_cam);
      step_ratio = std::max(step_ratio, pair_ratio);
      step_obstacle = pair_ratio > 1.0;
    }
    const size_t cs = static_cast<size_t>(c);
    ObstacleCell out;
    out.x = static_cast<float>((ox + gx + 0.5) * cell);
    out.y = static_cast<float>((oy + gy + 0.5) * cell);
    out.height = sum_z_[cs];
    out.negative_edge = edge_ratio_[cs] > 1.0f;
    out.traversability = std::max(static_cast<float>(step_ratio), edge_ratio_[cs]);
    out.obstacle = step_obstacle || out.negative_edge;
    cell_obstacle_[cs] = out.obstacle;
    result->cells.push_back(out);
  }
  uint8_t* obstacle = pts->obstacle.data();
  const uint8_t* cell_obstacle = cell_obstacle_.data();
  int64_t obstacle_points = 0;
  for (size_t i = 0; i < np; ++i) {
    const int32_t c = cell_of_point[i];
    obstacle[i] = c >= 0 && cell_obstacle[static_cast<size_t>(c)];
    obstacle_points += obstacle[i];
  }
  result->obstacle_points = obstacle_points;
  return Status::Ok();
}

}  // namespace cairn
