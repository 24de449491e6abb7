#include "stereo/stereo_depth.h"

#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <vector>

#include "stereo/stereo_error_model.h"

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
  const size_t begin = static_cast<size_t>(y0) * w, end = static_cast<size_t>(y1) * w;
  const int16_t* disparity = out->disparity.data();
  // Depth and sigma of one disparity value.
  const auto at = [&](int16_t d, float* depth, float* sigma) {
    const double disp = static_cast<double>(d) / kDisparityScale + input.disparity_offset_px;
    if (!geometry || d == kInvalidDisparity || disp <= 0.0) {
      *depth = nan;
      *sigma = nan;
      return;
    }
    const double z = fb / disp;
    *depth = static_cast<float>(z);
    *sigma = static_cast<float>(model.DepthError(z));
  };
  if (!geometry) {
    std::fill(out->depth.begin() + static_cast<ptrdiff_t>(begin),
              out->depth.begin() + static_cast<ptrdiff_t>(end), nan);
    std::fill(out->depth_sigma.begin() + static_cast<ptrdiff_t>(begin),
              out->depth_sigma.begin() + static_cast<ptrdiff_t>(end), nan);
    return;
  }
  // They depend on the value alone, and a matcher's values span a few thousand: a table of the
  // values that occur gives the same floats at a fraction of the divisions.
  int lo = INT16_MAX, hi = INT16_MIN;
  for (size_t i = begin; i < end; ++i) {
    const int d = disparity[i];
    if (d == kInvalidDisparity) continue;
    lo = d < lo ? d : lo;
    hi = d > hi ? d : hi;
  }
  constexpr int kMaxTable = 8192;
  if (lo > hi || hi - lo >= kMaxTable || end - begin < 4 * static_cast<size_t>(hi - lo + 1)) {
    for (size_t i = begin; i < end; ++i) at(disparity[i], &out->depth[i], &out->depth_sigma[i]);
    return;
  }
  // Per thread (the matchers call this from their workers, a band each), at its largest from the
  // start: the matching path allocates nothing after each worker's first image.
  thread_local std::vector<float> table;
  table.reserve(2 * static_cast<size_t>(kMaxTable));
  table.resize(2 * static_cast<size_t>(hi - lo + 1));
  for (int d = lo; d <= hi; ++d) {
    at(static_cast<int16_t>(d), &table[2 * static_cast<size_t>(d - lo)],
       &table[2 * static_cast<size_t>(d - lo) + 1]);
  }
  for (size_t i = begin; i < end; ++i) {
    const int16_t d = disparity[i];
    if (d == kInvalidDisparity) {
      out->depth[i] = nan;
      out->depth_sigma[i] = nan;
      continue;
    }
    const float* e = &table[2 * static_cast<size_t>(d - lo)];
    out->depth[i] = e[0];
    out->depth_sigma[i] = e[1];
  }
}

}  // namespace cairn
