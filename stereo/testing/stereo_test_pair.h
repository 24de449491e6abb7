#pragma once
// Synthetic rectified pairs for the stereo backend tests: random texture on the left; the right
// image is the left shifted by `shift` px (by `shift + lower_shift` in the lower half), plus
// uniform noise of +-noise grey levels, so that clear matches, ambiguous ones and occlusions occur.

#include <algorithm>
#include <cstdint>
#include <random>
#include <vector>

#include "stereo/sgm_options.h"
#include "stereo/stereo_matcher_interface.h"

namespace cairn {

struct TestStereoPair {
  int w = 0, h = 0;
  std::vector<uint8_t> l, r;

  static TestStereoPair Make(int w, int h, int shift, uint32_t seed, int noise = 0,
                             int lower_shift = 0) {
    std::mt19937 rng(seed);
    TestStereoPair p{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h),
                     std::vector<uint8_t>(static_cast<size_t>(w) * h)};
    for (auto& v : p.l) v = static_cast<uint8_t>(rng() & 0xFF);
    for (int y = 0; y < h; ++y) {
      for (int x = 0; x < w; ++x) {
        const int src = std::min(w - 1, x + shift + (y > h / 2 ? lower_shift : 0));
        int v = p.l[static_cast<size_t>(y) * w + src];
        if (noise > 0) v += static_cast<int>(rng() % (2 * noise)) - noise;
        p.r[static_cast<size_t>(y) * w + x] = static_cast<uint8_t>(std::clamp(v, 0, 255));
      }
    }
    return p;
  }

  StereoMatcherInput input() const {
    StereoMatcherInput in;
    in.left = l.data();
    in.right = r.data();
    in.width = w;
    in.height = h;
    in.stride = w;
    return in;
  }
};

// The FPGA mode (raster paths) with the disparity range the offload tests use.
inline SgmOptions FpgaModeTestOptions() {
  SgmOptions o;
  o.raster_paths = true;
  o.num_disparities = 32;
  return o;
}

}  // namespace cairn
