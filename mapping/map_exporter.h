#pragma once
// Map exports for other tools: point clouds as PCD (binary) and PLY (binary little endian), with
// x y z, rgb and the obstacle flag; occupancy trees as OctoMap .bt (free/occupied) or .ot (full
// log-odds); traversability grids as PNG + YAML in the ROS map_server convention.

#include <string>
#include <vector>

#include <octomap/OcTree.h>

#include "common/status.h"
#include "mapping/grid_map.h"
#include "mapping/voxel_cloud.h"

namespace cairn {

class MapExporter {
 public:
  static Status WritePcd(const std::vector<CloudPoint>& points, const std::string& path);
  static Status WritePly(const std::vector<CloudPoint>& points, const std::string& path);
  // By extension: .pcd or .ply.
  static Status WriteCloud(const std::vector<CloudPoint>& points, const std::string& path);
  // By extension: .bt (maximum likelihood, pruned copy) or .ot (log-odds).
  static Status WriteOctree(const octomap::OcTree& tree, const std::string& path);
  // `png_path` ends in .png; the YAML goes next to it with the same stem. Pixels: 0 (black)
  // untraversable (value > 1), 254 traversable, 205 unknown; mode trinary, origin the lower-left
  // cell corner, image row 0 the map's top (largest y), as map_server expects.
  static Status WriteGridMap(const GridMap& grid, const std::string& png_path);

  // Reads clouds written by WritePcd/WritePly back (round-trip tests, `cairn map` commands).
  static Expected<std::vector<CloudPoint>> ReadCloud(const std::string& path);
};

}  // namespace cairn
