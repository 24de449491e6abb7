#pragma once
// A 2-D grid of values in a gravity-aligned frame, as handed to local planners and exporters.

#include <cmath>
#include <string>
#include <vector>

namespace cairn {

struct GridMap {
  std::string frame;          // e.g. "local/3"
  double resolution = 0.05;   // m per cell
  double origin_x = 0.0;      // m, lower-left corner of cell (0, 0)
  double origin_y = 0.0;
  int width = 0;              // cells along x
  int height = 0;             // cells along y
  // Row-major, row 0 at origin_y; NaN where unknown. For traversability maps, > 1 is untraversable.
  std::vector<float> values;

  float at(int x, int y) const { return values[static_cast<size_t>(y) * static_cast<size_t>(width) + static_cast<size_t>(x)]; }
  bool known(int x, int y) const { return !std::isnan(at(x, y)); }
};

}  // namespace cairn
