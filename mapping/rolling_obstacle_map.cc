#include "mapping/rolling_obstacle_map.h"

#include <cmath>
#include <limits>

namespace cairn {
namespace {
constexpr float kUnknown = std::numeric_limits<float>::quiet_NaN();
int64_t Mod(int64_t a, int64_t n) { return ((a % n) + n) % n; }
}  // namespace

RollingObstacleMap::RollingObstacleMap(const RollingMapOptions& options)
    : options_(options), n_(static_cast<int>(options.cells)), res_(options.cell_size),
      values_(static_cast<size_t>(n_) * static_cast<size_t>(n_), kUnknown),
      scratch_(values_.size()) {
  ox_ = oy_ = -n_ / 2;
}

size_t RollingObstacleMap::Slot(int64_t ix, int64_t iy) const {
  return static_cast<size_t>(Mod(iy, n_) * n_ + Mod(ix, n_));
}

void RollingObstacleMap::Clear() { std::fill(values_.begin(), values_.end(), kUnknown); }

void RollingObstacleMap::Recenter(const Eigen::Vector2d& robot_xy) {
  const int64_t nx = static_cast<int64_t>(std::floor(robot_xy.x() / res_)) - n_ / 2;
  const int64_t ny = static_cast<int64_t>(std::floor(robot_xy.y() / res_)) - n_ / 2;
  if (nx == ox_ && ny == oy_) return;
  if (std::abs(nx - ox_) >= n_ || std::abs(ny - oy_) >= n_) {
    Clear();
  } else {
    // Forget the columns and rows that leave the window; their slots are reused for those entering.
    for (int64_t ix = ox_; ix < ox_ + n_; ++ix) {
      if (ix >= nx && ix < nx + n_) continue;
      for (int64_t iy = oy_; iy < oy_ + n_; ++iy) values_[Slot(ix, iy)] = kUnknown;
    }
    for (int64_t iy = oy_; iy < oy_ + n_; ++iy) {
      if (iy >= ny && iy < ny + n_) continue;
      for (int64_t ix = ox_; ix < ox_ + n_; ++ix) values_[Slot(ix, iy)] = kUnknown;
    }
  }
  ox_ = nx;
  oy_ = ny;
}

void RollingObstacleMap::Integrate(const std::vector<ObstacleCell>& cells) {
  const float a = static_cast<float>(options_.low_pass);
  for (const ObstacleCell& c : cells) {
    const int64_t ix = static_cast<int64_t>(std::floor(c.x / res_));
    const int64_t iy = static_cast<int64_t>(std::floor(c.y / res_));
    if (!Inside(ix, iy)) continue;
    float& v = values_[Slot(ix, iy)];
    v = std::isnan(v) ? c.traversability : (1.0f - a) * v + a * c.traversability;
  }
}

float RollingObstacleMap::At(const Eigen::Vector2d& xy) const {
  const int64_t ix = static_cast<int64_t>(std::floor(xy.x() / res_));
  const int64_t iy = static_cast<int64_t>(std::floor(xy.y() / res_));
  return Inside(ix, iy) ? values_[Slot(ix, iy)] : kUnknown;
}

void RollingObstacleMap::Rebase(const Eigen::Isometry3d& T_old_new, const Eigen::Vector2d& robot_xy_new) {
  const int64_t nx = static_cast<int64_t>(std::floor(robot_xy_new.x() / res_)) - n_ / 2;
  const int64_t ny = static_cast<int64_t>(std::floor(robot_xy_new.y() / res_)) - n_ / 2;
  for (int iy = 0; iy < n_; ++iy) {
    for (int ix = 0; ix < n_; ++ix) {
      const Eigen::Vector3d p_new((nx + ix + 0.5) * res_, (ny + iy + 0.5) * res_, 0.0);
      const Eigen::Vector3d p_old = T_old_new * p_new;
      scratch_[static_cast<size_t>(iy) * static_cast<size_t>(n_) + static_cast<size_t>(ix)] = At(p_old.head<2>());
    }
  }
  ox_ = nx;
  oy_ = ny;
  for (int iy = 0; iy < n_; ++iy) {
    for (int ix = 0; ix < n_; ++ix) values_[Slot(ox_ + ix, oy_ + iy)] = scratch_[static_cast<size_t>(iy) * static_cast<size_t>(n_) + static_cast<size_t>(ix)];
  }
}

GridMap RollingObstacleMap::Snapshot() const {
  GridMap g;
  g.resolution = res_;
  g.origin_x = static_cast<double>(ox_) * res_;
  g.origin_y = static_cast<double>(oy_) * res_;
  g.width = g.height = n_;
  g.values.resize(values_.size());
  for (int iy = 0; iy < n_; ++iy) {
    for (int ix = 0; ix < n_; ++ix) g.values[static_cast<size_t>(iy) * static_cast<size_t>(n_) + static_cast<size_t>(ix)] = values_[Slot(ox_ + ix, oy_ + iy)];
  }
  return g;
}

}  // namespace cairn
