#pragma once
// Raster-path SGM (sgm raster_paths, the path set a streaming FPGA core computes in one top-down
// pass: left, up-left, up, up-right) smooths every pixel toward the rows above it. Where the
// disparity changes with the row, as on the ground ahead of a camera, that pulls the disparity
// toward the rows above, i.e. too small: in the simulator the ground came out 1.4 cm (rover) and
// 3 cm (hexacopter) too deep, while the symmetric CPU path set was unbiased. Matching the
// vertically flipped pair as well runs the same paths bottom-up, with the opposite bias; where
// the two disparities agree their average is unbiased and less noisy. It costs a second match per
// pair and works on any backend, so the FPGA and its CPU fallback still agree bit for bit.

#include <cstdint>
#include <string>
#include <vector>

#include "stereo/stereo_matcher_interface.h"

namespace cairn {

class BidirectionalRasterMatcher final : public StereoMatcher {
 public:
  // `inner` must outlive this object. Disparities of the two passes that differ by more than
  // `max_diff` (1/16 px) are invalid; `pixel_error_px` is the depth sigma's image coordinate
  // error (eq. 5.2), as the inner matcher's.
  BidirectionalRasterMatcher(StereoMatcher& inner, int max_diff, double pixel_error_px);

  // The inner matcher's name (which may change, e.g. on an FPGA fallback) + "-bidirectional".
  std::string_view name() const override;
  // The inner matcher on the pair and on the pair flipped upside down, combined per pixel: the
  // average (rounded half to even) where both are valid and agree, the one that is valid where
  // only one is, invalid where they disagree. Depth and its sigma follow from the combined
  // disparity. Buffers grow only when the image size does.
  Status Match(const StereoMatcherInput& input, StereoMatcherOutput* output) override;

  // Pixels of the last pair by how the passes compared (diagnostics).
  struct Counts {
    int64_t agreed = 0, disagreed = 0, one_pass = 0;
  };
  const Counts& last_counts() const { return counts_; }

 private:
  StereoMatcher& inner_;
  int max_diff_;
  double pixel_error_px_;
  mutable std::string name_;
  std::vector<uint8_t> flipped_left_, flipped_right_;
  StereoMatcherOutput flipped_;
  Counts counts_;
};

}  // namespace cairn
