#include "stereo/bidirectional_raster_matcher.h"

#include <algorithm>
#include <cstdlib>

#include "stereo/stereo_depth.h"

namespace cairn {
namespace {

// Rows of a w x h image with `stride` bytes per row, bottom row first, into a packed buffer.
void FlipRows(const uint8_t* src, int w, int h, int stride, std::vector<uint8_t>* dst) {
  dst->resize(static_cast<size_t>(w) * static_cast<size_t>(h));
  for (int y = 0; y < h; ++y) {
    std::copy_n(src + static_cast<size_t>(h - 1 - y) * static_cast<size_t>(stride), w,
                dst->data() + static_cast<size_t>(y) * static_cast<size_t>(w));
  }
}

// (a + b) / 2 rounded half to even: truncation would lose 1/32 px on every odd sum, a bias of its
// own toward smaller disparities.
int16_t Average(int16_t a, int16_t b) {
  const int sum = a + b;
  return static_cast<int16_t>((sum + ((sum >> 1) & 1)) >> 1);
}

}  // namespace

BidirectionalRasterMatcher::BidirectionalRasterMatcher(StereoMatcher& inner, int max_diff, double pixel_error_px)
    : inner_(inner), max_diff_(max_diff), pixel_error_px_(pixel_error_px) {}

std::string_view BidirectionalRasterMatcher::name() const {
  name_ = std::string(inner_.name()) + "-bidirectional";
  return name_;
}

Status BidirectionalRasterMatcher::Match(const StereoMatcherInput& input, StereoMatcherOutput* output) {
  CAIRN_RETURN_IF_ERROR(inner_.Match(input, output));
  const int w = input.width, h = input.height;
  FlipRows(input.left, w, h, input.stride, &flipped_left_);
  FlipRows(input.right, w, h, input.stride, &flipped_right_);
  StereoMatcherInput flipped = input;
  flipped.left = flipped_left_.data();
  flipped.right = flipped_right_.data();
  flipped.stride = w;
  CAIRN_RETURN_IF_ERROR(inner_.Match(flipped, &flipped_).WithContext("flipped pass"));
  counts_ = Counts{};
  for (int y = 0; y < h; ++y) {
    int16_t* down = output->disparity.data() + static_cast<size_t>(y) * static_cast<size_t>(w);
    const int16_t* up = flipped_.disparity.data() + static_cast<size_t>(h - 1 - y) * static_cast<size_t>(w);
    for (int x = 0; x < w; ++x) {
      const bool a = down[x] != kInvalidDisparity, b = up[x] != kInvalidDisparity;
      if (a && b) {
        if (std::abs(down[x] - up[x]) <= max_diff_) {
          down[x] = Average(down[x], up[x]);
          ++counts_.agreed;
        } else {
          down[x] = kInvalidDisparity;
          ++counts_.disagreed;
        }
      } else if (a || b) {
        down[x] = a ? down[x] : up[x];
        ++counts_.one_pass;
      }
    }
  }
  ComputeStereoDepth(input, pixel_error_px_, output, 0, h);
  return Status::Ok();
}

}  // namespace cairn
