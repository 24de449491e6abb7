#pragma once
// Submaps cut from a real 3-D laser scan (OctoMap's scan.dat.bz2 in ../shared/data/octomap: one
// outdoor scan, x y z per line, the scanner at the origin, z up) for matching tests on real
// geometry. Obstacles are marked with the 2.5-D height-grid rule of the obstacle classifier
// (thesis 5.1.1): a point higher than the lowest point of its neighbourhood by more than a step.
// The occupancy tree is ray-cast from the scanner, so known and unknown space are real too.

#include <bzlib.h>

#include <cmath>
#include <cstdio>
#include <memory>
#include <sstream>
#include <string>
#include <unordered_map>
#include <vector>

#include <Eigen/Geometry>

#include "mapping/submap.h"
#include "mapping/testing/rock_field_scene.h"
#include "mapping/voxel_cloud.h"

namespace cairn::testing {

// The scan's points; empty when the file cannot be read.
inline std::vector<Eigen::Vector3d> ReadBzip2Scan(const std::string& path) {
  std::vector<Eigen::Vector3d> points;
  FILE* file = std::fopen(path.c_str(), "rb");
  if (file == nullptr) return points;
  int error = BZ_OK;
  BZFILE* bz = BZ2_bzReadOpen(&error, file, 0, 0, nullptr, 0);
  std::string text;
  char buffer[1 << 16];
  while (error == BZ_OK) {
    const int n = BZ2_bzRead(&error, bz, buffer, sizeof(buffer));
    if (n > 0) text.append(buffer, static_cast<size_t>(n));
  }
  const bool complete = error == BZ_STREAM_END;
  BZ2_bzReadClose(&error, bz);
  std::fclose(file);
  if (!complete) return points;
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    std::istringstream fields(line);
    Eigen::Vector3d p;
    if (fields >> p.x() >> p.y() >> p.z()) points.push_back(p);
  }
  return points;
}

// Obstacle flags: higher than the lowest point within `cell` (xy, and the 8 neighbouring cells) by
// more than `step`.
inline std::vector<bool> HeightGridObstacles(const std::vector<Eigen::Vector3d>& points, double cell = 0.25,
                                             double step = 0.15) {
  auto key = [cell](double x, double y) {
    return (static_cast<int64_t>(std::floor(x / cell)) << 32) ^ (static_cast<int64_t>(std::floor(y / cell)) & 0xffffffff);
  };
  std::unordered_map<int64_t, double> lowest;
  for (const Eigen::Vector3d& p : points) {
    auto [it, added] = lowest.emplace(key(p.x(), p.y()), p.z());
    if (!added) it->second = std::min(it->second, p.z());
  }
  std::vector<bool> obstacle(points.size());
  for (size_t i = 0; i < points.size(); ++i) {
    double low = points[i].z();
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        if (auto it = lowest.find(key(points[i].x() + dx * cell, points[i].y() + dy * cell)); it != lowest.end())
          low = std::min(low, it->second);
    obstacle[i] = points[i].z() - low > step;
  }
  return obstacle;
}

struct ScanCrop {
  Eigen::AlignedBox2d xy;  // world region the submap keeps
  Eigen::Isometry3d T_world_submap = Eigen::Isometry3d::Identity();
};

// The crop's points in the submap frame, voxel-filtered at 0.05 m on the submap's own grid, and a
// tree cast from the scanner (world origin) to them.
inline std::shared_ptr<const Submap> ScanSubmap(const std::vector<Eigen::Vector3d>& scan,
                                                const std::vector<bool>& obstacle, const ScanCrop& crop,
                                                double max_range = 30.0) {
  SubmapOptions options;
  VoxelCloud cloud(options.cloud_resolution, scan.size() / 2 + 16);
  const Eigen::Isometry3d T_submap_world = crop.T_world_submap.inverse();
  for (size_t i = 0; i < scan.size(); ++i) {
    if (!crop.xy.contains(scan[i].head<2>()) || scan[i].norm() > max_range) continue;
    cloud.Add((T_submap_world * scan[i]).cast<float>(), 128, 128, 128, obstacle[i]);
  }
  return RayCastSubmap(cloud.Points(), {T_submap_world.translation()}, options, max_range);
}

}  // namespace cairn::testing
