#include "fpga/stereo_depth.h"

#include <limits>

#include "mapping/stereo_error_model.h"

namespace cairn {

void ResizeStereoOutput(int width, int height, StereoMatcherOutput* out) {
  const size_t n = static_cast<size_t>(width) * height;
  if (out->width == width && out->height == height && out->disparity.size() == n) return;
  out->width = width;
  out->height = height;
  out->disparity.resize(n);
  out->depth.resize(n);
  out->depth_sigma.resize(n);
}

void ComputeStereoDepth(const StereoMatcherInput& input, double pixel_error_px,
                        StereoMatcherOutput* out, int y0, int y1) {
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const bool geometry = input.focal_px > 0.0 && input.baseline_m > 0.0;
  const StereoErrorModel model(geometry ? input.focal_px : 1.0, geometry ? input.baseline_m : 1.0,
                               pixel_error_px);
  const double fb = input.focal_px * input.baseline_m;
  const int w = out->width;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < w; ++x) {
      const size_t i = static_cast<size_t>(y) * w + x;
      const int16_t d = out->disparity[i];
      const double disp = static_cast<double>(d) / kDisparityScale + input.disparity_offset_px;
      if (!geometry || d == kInvalidDisparity || disp <= 0.0) {
        out->depth[i] = nan;
        out->depth_sigma[i] = nan;
        continue;
      }
      const double z = fb / disp;
      out->depth[i] = static_cast<float>(z);
      out->depth_sigma[i] = static_cast<float>(model.DepthError(z));
    }
  }
}

}  // namespace cairn
