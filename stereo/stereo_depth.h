#pragma once
// Depth and depth sigma from a fixed-point disparity image, shared by every StereoMatcher backend
// so that the CPU and FPGA backends hand the pipeline the same numbers.

#include "stereo/stereo_matcher_interface.h"

namespace cairn {

// Sizes the output buffers for the input's image size (no allocation when they already fit).
void ResizeStereoOutput(int width, int height, StereoMatcherOutput* out);

// Rows [y0, y1) of out->depth and out->depth_sigma from out->disparity; NaN where the disparity is
// invalid, not positive after the offset, or the input has no focal length / baseline.
void ComputeStereoDepth(const StereoMatcherInput& input, double pixel_error_px,
                        StereoMatcherOutput* out, int y0, int y1);

}  // namespace cairn
