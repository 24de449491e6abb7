#pragma once
// Builds the procedural planetary-analogue terrain a world describes: a height grid of multi-octave
// noise with small craters, boulders and one large crater with a steep rim, and an albedo texture
// with detail at several scales (boulders darker than the regolith) plus a tile of fine grain.
// Everything is a function of the options and their seed, the same bits on every machine.

#include <vector>

#include <Eigen/Core>

#include "sim/terrain.h"
#include "sim/world_options.h"

namespace cairn::sim {

class TerrainGenerator {
 public:
  static TerrainGrids Generate(const WorldOptions& options);

 private:
  // The texture over the grid `grids` already spans; `rocks` are (x, y, radius, height).
  static void BuildAlbedo(const WorldOptions& options, const std::vector<Eigen::Vector4d>& rocks,
                          TerrainGrids* grids);
};

}  // namespace cairn::sim
