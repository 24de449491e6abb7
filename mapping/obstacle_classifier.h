#pragma once
// Obstacle classification on one depth image (thesis 5.1.1): negative edges column by column
// (depth jump, minimal slope eq. 5.1), then a gravity-aligned 2.5-D height grid where a cell is an
// obstacle when the largest height difference in its window exceeds h_max + delta_d, delta_d the
// eq. 5.4 error of the distance between the two extreme cells seen from the camera, or when a pair
// of cells within step_tie_tolerance of those two does so with its own delta_d. Cells of fewer
// than min_cell_points points stay out of the grid.

#include <cstdint>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/depth_image.h"
#include "mapping/mapping_options.h"
#include "stereo/stereo_error_model.h"

namespace cairn {

// One observed height-grid cell, in the local (gravity-aligned) frame of the image's pose.
struct ObstacleCell {
  float x = 0.0f, y = 0.0f;        // cell centre
  float height = 0.0f;             // mean height of its points
  float traversability = 0.0f;     // max(h_diff / (h_max + delta_d), s_min / max_slope); > 1: obstacle
  uint8_t obstacle = 0;
  uint8_t negative_edge = 0;
};

struct ObstacleResult {
  std::vector<ObstacleCell> cells;
  int64_t negative_edges = 0;    // edge pixels among the kept points
  int64_t obstacle_points = 0;
  void Clear() {
    cells.clear();
    negative_edges = 0;
    obstacle_points = 0;
  }
};

class ObstacleClassifier {
 public:
  // `range` bounds the height grid (the projector's range); buffers are sized here once.
  ObstacleClassifier(const ObstacleOptions& options, const StereoCamera& camera,
                     const StereoErrorModel& model, double range);

  // Sets points->obstacle from the image the points were made of and fills `result` (cleared).
  Status Classify(const DepthImage& image, CameraPoints* points, ObstacleResult* result);

  // Eq. 5.1: least slope any surface between p (top) and q (bottom, local frame) can have.
  static double MinimalSlope(const Eigen::Vector3d& p, const Eigen::Vector3d& q);

  const ObstacleOptions& options() const { return options_; }

 private:
  struct Edge {
    uint32_t pixel;
    float ratio;  // s_min / max_slope
  };
  struct WindowCell {
    int cell;
    Eigen::Vector3d p_cam;  // centre at its mean height
  };
  void FindNegativeEdges(const DepthImage& image, const Eigen::Isometry3d& T_local_cam);
  // Largest (h_q - h_p) / (h_max + delta_d(p, q)) over the window's pairs of a top q within
  // step_tie_tolerance of its highest cell and a foot p within it of its lowest that rise by more
  // than h_max; 0 when none does.
  template <typename CentreCam>
  double DecisivePairRatio(int gx, int gy, float zmin, float zmax, const CentreCam& centre_cam);

  ObstacleOptions options_;
  StereoCamera camera_;
  StereoErrorModel model_;
  int n_ = 0;  // grid cells per side
  // Per column: depth and row of the last valid pixel above.
  std::vector<float> last_depth_;
  std::vector<int> last_row_;
  std::vector<Edge> edges_;
  // Height grid, n_ x n_, reset through touched_.
  std::vector<float> sum_z_;
  std::vector<int32_t> count_;
  std::vector<float> edge_ratio_;
  std::vector<int32_t> cell_of_point_;
  std::vector<int32_t> touched_;
  std::vector<uint8_t> cell_obstacle_;
  std::vector<WindowCell> tops_, feet_;  // DecisivePairRatio's candidates, kept for their capacity
};

}  // namespace cairn
