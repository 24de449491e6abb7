#pragma once
// Rolling, robot-centred traversability map (thesis 5.1.1): a fixed ring of cells that scrolls
// with the robot, so moving never copies the map, and a temporal low-pass over the per-image
// classification results.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/grid_map.h"
#include "mapping/mapping_options.h"
#include "mapping/obstacle_classifier.h"

namespace cairn {

class RollingObstacleMap {
 public:
  explicit RollingObstacleMap(const RollingMapOptions& options);

  // Moves the window so that it is centred on `robot_xy` (local frame); cells that leave are
  // forgotten.
  void Recenter(const Eigen::Vector2d& robot_xy);
  // Blends the cells of one classified image (same local frame) into the map.
  void Integrate(const std::vector<ObstacleCell>& cells);
  // After a frame switch: re-expresses the map in the new frame (T_old_new from the filter),
  // nearest-cell resampling, and centres it on `robot_xy_new`.
  void Rebase(const Eigen::Isometry3d& T_old_new, const Eigen::Vector2d& robot_xy_new);
  void Clear();

  // Traversability at a local position; NaN when unknown or outside the window.
  float At(const Eigen::Vector2d& xy) const;
  // A copy in ordinary row-major order for planners and exporters.
  GridMap Snapshot() const;

  int cells() const { return n_; }
  double cell_size() const { return res_; }

 private:
  size_t Slot(int64_t ix, int64_t iy) const;
  bool Inside(int64_t ix, int64_t iy) const { return ix >= ox_ && iy >= oy_ && ix < ox_ + n_ && iy < oy_ + n_; }

  RollingMapOptions options_;
  int n_;
  double res_;
  int64_t ox_ = 0, oy_ = 0;  // global index of the window's lower-left cell
  std::vector<float> values_;
  std::vector<float> scratch_;
};

}  // namespace cairn
