#pragma once
// Backend-neutral dense stereo matcher. The CPU (scalar golden model, Highway SIMD) and the later
// FPGA backend all implement this interface and must produce the same disparity bit for bit.
//
// Disparity fixed point: int16 in 1/16 pixel (kDisparityScale = 16, 4 fractional bits), value =
// round(16 * d) where d is the left-image disparity in pixels (x_right = x_left - d).
// kInvalidDisparity marks pixels without a trustworthy match (occluded, ambiguous, speckle).

#include <cstdint>
#include <string_view>
#include <vector>

#include "common/status.h"

namespace cairn {

inline constexpr int kDisparityScale = 16;
inline constexpr int kDisparityFractionBits = 4;
inline constexpr int16_t kInvalidDisparity = INT16_MIN;

// One rectified pair. Plain memory, no timestamps: the caller owns the pixels and keeps them alive
// during Match(). Depth is produced when focal_px and baseline_m are positive.
struct StereoMatcherInput {
  const uint8_t* left = nullptr;   // 8-bit gray, row-major
  const uint8_t* right = nullptr;  // 8-bit gray, same size and stride as left
  int width = 0;
  int height = 0;
  int stride = 0;  // bytes between rows of both images
  double focal_px = 0.0;
  double baseline_m = 0.0;
  // Added to the disparity before triangulating (Middlebury's doffs; 0 for ordinary rigs).
  double disparity_offset_px = 0.0;
};

// Buffers are resized only when the image size changes, so a caller that reuses one output struct
// does not allocate per frame.
struct StereoMatcherOutput {
  int width = 0;
  int height = 0;
  std::vector<int16_t> disparity;    // 1/16 px, kInvalidDisparity where invalid
  std::vector<float> depth;          // metres along the optical axis; NaN where invalid
  std::vector<float> depth_sigma;    // metres, thesis eq. 5.2 (c); NaN where invalid

  int16_t disparity_at(int x, int y) const { return disparity[static_cast<size_t>(y) * width + x]; }
};

class StereoMatcher {
 public:
  virtual ~StereoMatcher() = default;
  virtual std::string_view name() const = 0;
  virtual Status Match(const StereoMatcherInput& input, StereoMatcherOutput* output) = 0;
};

}  // namespace cairn
