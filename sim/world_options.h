#pragma once
// The simulated world as described by a small YAML file (`cairn sim --world`). Everything is
// derived from these numbers and the seed, so a world file plus a seed reproduces a mission.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "common/options_visitor.h"

namespace cairn::sim {

struct WorldOptions {
  double size = 60.0;             // side of the square world, centred on the origin
  double resolution = 0.1;        // height-grid spacing
  int64_t seed = 1;
  double relief = 1.2;            // amplitude of the multi-octave height field
  double crater_density = 40.0;   // craters per hectare (radius 0.5-4 m)
  double rock_density = 600.0;    // boulders per hectare (radius 0.05-0.5 m times rock_size)
  double rock_size = 1.0;         // scale of every boulder's radius and height
  bool big_crater = true;         // one large crater with a steep rim (cliff-like negative edge)
  double sun_azimuth = 135.0;     // from +x towards +y
  double sun_elevation = 35.0;
  double albedo_contrast = 0.35;  // relative albedo variation of the texture
  // Optional static landmark tags (e.g. on a lander): x, y of the lander, 0 or 2 values.
  std::vector<double> lander = {6.0, -4.0};
  // Radius of the level, boulder-free ground the lander stands on (its landing site), blending
  // into the terrain over another half of it; 0 leaves the terrain as it is.
  double landing_site = 5.0;
  double tag_size = 0.16;         // edge of the tags' black border square
  // A rover's tag on its deck facing up, for the multicopter above (larger: it is seen from 3-5 m);
  // 0: none.
  double roof_tag_size = 0.4;
  // Man-made structures (a habitat, walls, crates, a lander's body): blocks with vertical sides and
  // a level top on the ground, six values each: x, y (m), yaw (deg), length, width, height (m). The
  // top stands `height` above the lowest ground under it. Sides square to the height grid (yaw a
  // multiple of 90 deg) are planes; at other angles they come out as steps of one grid cell.
  std::vector<double> structures;
  static constexpr size_t kStructureValues = 6;
  static constexpr size_t kMaxStructures = 64;

  void Visit(OptionsVisitor& v) {
    v.Number("size", size, 10.0, 400.0, "m");
    v.Number("resolution", resolution, 0.02, 1.0, "m");
    v.Integer("seed", seed, 0, int64_t{1} << 62, "");
    v.Number("relief", relief, 0.0, 20.0, "m");
    v.Number("crater_density", crater_density, 0.0, 2000.0, "1/ha");
    v.Number("rock_density", rock_density, 0.0, 20000.0, "1/ha");
    v.Number("rock_size", rock_size, 0.1, 10.0, "");
    v.Flag("big_crater", big_crater);
    v.Number("sun_azimuth", sun_azimuth, -360.0, 360.0, "deg");
    v.Number("sun_elevation", sun_elevation, 5.0, 90.0, "deg");
    v.Number("albedo_contrast", albedo_contrast, 0.0, 0.9, "");
    v.Numbers("lander", lander, 0, 2, -200.0, 200.0, "m");
    v.Number("landing_site", landing_site, 0.0, 50.0, "m");
    v.Number("tag_size", tag_size, 0.02, 2.0, "m");
    v.Number("roof_tag_size", roof_tag_size, 0.0, 0.4, "m");
    v.Numbers("structures", structures, 0, kStructureValues * kMaxStructures, -400.0, 400.0,
              "groups of x y (m), yaw (deg), length width height (m)");
  }
  Status Validate() const {
    if (size / resolution > 8000.0) {
      return InvalidArgumentError("size / resolution exceeds 8000 cells per side (memory)");
    }
    if (lander.size() == 1) return InvalidArgumentError("lander needs x and y (or nothing)");
    if (lander.size() == 2 && (std::abs(lander[0]) > size / 2 - 2 || std::abs(lander[1]) > size / 2 - 2)) {
      return InvalidArgumentError("lander must lie at least 2 m inside the world");
    }
    if (structures.size() % kStructureValues != 0) {
      return InvalidArgumentError(
          "structures needs six values per structure (x, y, yaw, length, width, height), got " +
          std::to_string(structures.size()));
    }
    for (size_t i = 0; i < structures.size(); i += kStructureValues) {
      const double* b = &structures[i];
      const std::string which = "structure " + std::to_string(i / kStructureValues) + ": ";
      if (std::hypot(b[3], b[4]) / 2 + std::max(std::abs(b[0]), std::abs(b[1])) > size / 2 - 1) {
        return InvalidArgumentError(which + "must lie at least 1 m inside the world");
      }
      if (!(b[3] >= 2 * resolution && b[4] >= 2 * resolution && b[3] <= 100 && b[4] <= 100)) {
        return InvalidArgumentError(which + "length and width must be 2 grid cells to 100 m");
      }
      if (!(b[5] > 0.0 && b[5] <= 20.0)) return InvalidArgumentError(which + "height must be in (0, 20] m");
    }
    return Status::Ok();
  }
};

}  // namespace cairn::sim
