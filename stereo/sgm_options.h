#pragma once
// Semi-Global Matching parameters (Hirschmueller 2008) for every StereoMatcher backend.

#include <cstdint>

#include "common/options_visitor.h"

namespace cairn {

enum class SgmBackend { kScalar, kSimd };

struct SgmOptions {
  int64_t min_disparity = 0;       // px
  int64_t num_disparities = 128;   // px, a multiple of 16; disparities [min, min + num)
  // Center-symmetric census window: (w*h - 1) / 2 comparisons of opposite pixel pairs, <= 32.
  // 5x5 (12 bits) scored better than 9x7 on the Middlebury pairs and costs half as much.
  int64_t census_width = 5;
  int64_t census_height = 5;
  int64_t paths = 4;               // 4 (horizontal + vertical) or 8 (plus diagonals)
  // FPGA mode: the 4 paths that a streaming core can compute in raster order (left-to-right,
  // up-left, up, up-right) in one top-down pass, instead of `paths`' set; needs paths: 4.
  bool raster_paths = false;
  int64_t p1 = 6;                  // penalty for a disparity change of 1 px
  int64_t p2 = 40;                 // penalty for larger changes; census bits + 2 p2 <= 255
  // P2 falls to p2 * s / (s + |dI|) across an intensity step dI (but not below p1 + 1): depth
  // edges usually coincide with intensity edges. 0 keeps P2 constant.
  int64_t p2_intensity_scale = 16;  // gray levels
  int64_t uniqueness_percent = 5;  // best must beat the best non-neighbour by this margin
  bool lr_check = true;
  // px between the left and right integer winners. 1 drops many correct estimates on real road
  // frames (3-4 % of the image on two KITTI frames) for few wrong ones (docs/results.md).
  int64_t lr_max_diff = 2;
  bool subpixel = true;
  bool median = true;              // 3x3 median over valid pixels
  int64_t speckle_max_size = 100;  // px; smaller connected regions are invalidated, 0 = off
  int64_t speckle_max_diff = 32;   // 1/16 px between neighbours of one region
  bool fill_holes = false;         // fill invalid pixels from the farther row neighbour
  double pixel_error_px = 0.5;     // image coordinate sigma for the depth error (eq. 5.2)
  int64_t threads = 2;
  SgmBackend backend = SgmBackend::kSimd;

  void Visit(OptionsVisitor& v) {
    v.Integer("min_disparity", min_disparity, -1024, 1024, "px");
    v.Integer("num_disparities", num_disparities, 16, 512, "px");
    v.Integer("census_width", census_width, 3, 13, "px");
    v.Integer("census_height", census_height, 3, 13, "px");
    v.Integer("paths", paths, 4, 8, "");
    v.Flag("raster_paths", raster_paths);
    v.Integer("p1", p1, 1, 255, "cost");
    v.Integer("p2", p2, 2, 127, "cost");
    v.Integer("p2_intensity_scale", p2_intensity_scale, 0, 255, "gray levels");
    v.Integer("uniqueness_percent", uniqueness_percent, 0, 99, "%");
    v.Flag("lr_check", lr_check);
    v.Integer("lr_max_diff", lr_max_diff, 0, 16, "px");
    v.Flag("subpixel", subpixel);
    v.Flag("median", median);
    v.Integer("speckle_max_size", speckle_max_size, 0, 100000, "px");
    v.Integer("speckle_max_diff", speckle_max_diff, 0, 1024, "1/16 px");
    v.Flag("fill_holes", fill_holes);
    v.Number("pixel_error_px", pixel_error_px, 0.0, 10.0, "px");
    v.Integer("threads", threads, 1, 64, "");
    v.Choice("backend", backend, {{"scalar", SgmBackend::kScalar}, {"simd", SgmBackend::kSimd}});
  }

  Status Validate() const;
  int census_bits() const { return static_cast<int>((census_width * census_height - 1) / 2); }
  // P2' for every absolute intensity step 0..255 (what the kernels and the FPGA look up).
  void FillP2Table(uint8_t table[256]) const;
};

}  // namespace cairn
