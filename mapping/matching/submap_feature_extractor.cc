#include "mapping/matching/submap_feature_extractor.h"

#include <chrono>

#include "common/elapsed.h"
#include "common/heap_bytes.h"
#include "mapping/voxel_hash_map.h"

namespace cairn {
namespace {

// The grey-level search's default raster cell.
constexpr double kSearchCell = 0.2;  // m

// Area of the xy cells of kSearchCell that hold at least one point.
double GroundArea(const std::vector<Eigen::Vector3d>& cloud) {
  VoxelHashMap<uint8_t> cells(cloud.size() / 8);
  uint64_t key = 0;
  for (const Eigen::Vector3d& p : cloud) {
    if (VoxelKey::Of(Eigen::Vector3f(static_cast<float>(p.x()), static_cast<float>(p.y()), 0.0f),
                     static_cast<float>(1.0 / kSearchCell), &key))
      cells[key] = 1;
  }
  return static_cast<double>(cells.size()) * kSearchCell * kSearchCell;
}

}  // namespace

size_t SubmapFeatures::memory_bytes() const {
  return sizeof(*this) + HeapBytes(keypoints.points, keypoints.known_fraction, described.points,
                                   described.descriptors, described.frames, described.keypoint_index, cloud,
                                   cloud_grey, planes);
}

SubmapFeatures SubmapFeatureExtractor::Extract(const Submap& submap) const {
  SubmapFeatures f;
  const auto start = std::chrono::steady_clock::now();
  const SubmapSuitability suitability(options_.suitability);
  f.suitability = suitability.CheckCloud(submap.points());
  f.cloud.reserve(static_cast<size_t>(f.suitability.points));
  f.cloud_grey.reserve(static_cast<size_t>(f.suitability.points));
  for (const CloudPoint& c : submap.points()) {
    if (!c.p.allFinite()) continue;
    f.cloud.push_back(c.p.cast<double>());
    f.cloud_grey.push_back(static_cast<float>(c.r + c.g + c.b) / 3.0f);
    if (c.obstacle) f.obstacle_box_xy.extend(c.p.head<2>().cast<double>());
    f.cloud_box_xy.extend(c.p.head<2>().cast<double>());
  }
  if (f.suitability.suitable()) {
    f.keypoints = KeypointExtractor(options_.keypoints).Extract(submap);
    f.suitability = suitability.Check(submap, f.keypoints.points);
  }
  // The search turns about gravity: only for the 4-DoF matcher's features.
  if (!f.suitability.suitable() && f.suitability.reason != SuitabilityReason::kTooFewPoints &&
      frame_ == ShotFrame::kGravity && options_.min_search_area > 0.0) {
    f.ground_area = GroundArea(f.cloud);
    f.searchable = f.ground_area >= options_.min_search_area;
  }
  f.keypoint_ms = MillisecondsSince(start);
  if (!f.suitability.suitable()) {
    if (!f.searchable) {
      // Never aligned, but kept for the whole mission.
      f.cloud = std::vector<Eigen::Vector3d>();  // frees it (assigning {} would keep the capacity)
      f.cloud_grey = std::vector<float>();
    }
    return f;
  }

  f.planes = submap.structure().planes;
  f.lines = submap.structure().lines;
  const auto describe_start = std::chrono::steady_clock::now();
  GravityShotDescriptor descriptor(submap.points(), options_.descriptor, frame_);
  f.described = descriptor.ComputeAll(f.keypoints.points);
  f.descriptor_ms = MillisecondsSince(describe_start);
  return f;
}

}  // namespace cairn
