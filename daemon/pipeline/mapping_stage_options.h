#pragma once
// `mapping:` in a cairnd profile: the local mapping stage (thesis 5.1) on the dense depth images.
// When enabled it owns submap partitioning: its requests switch the filter's frame, and the
// interim `frame_switch` policy of the odometry is not used.

#include <cstdint>

#include "common/options_visitor.h"
#include "mapping/mapping_options.h"

namespace cairn {

struct MappingStageOptions {
  bool enabled = false;
  // Each finished submap is written as OUT/submaps/<robot>-<id>.submap (the wire format).
  bool write_submaps = true;
  // At the end of a run: the composed map as OUT/map.ply and OUT/map.bt, and the rolling obstacle
  // map as OUT/obstacles.png + .yaml.
  bool write_map = true;
  MappingOptions map;  // sections depth, obstacles, rolling_map, submap, partition, composition

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Flag("write_submaps", write_submaps);
    v.Flag("write_map", write_map);
    map.Visit(v);
  }
};

}  // namespace cairn
