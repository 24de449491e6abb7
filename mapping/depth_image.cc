#include "mapping/depth_image.h"

#include <cmath>
#include <limits>
#include <string>

namespace cairn {

Status DepthImage::Validate() const {
  if (width <= 0 || height <= 0) {
    return InvalidArgumentError("depth image has size " + std::to_string(width) + "x" + std::to_string(height));
  }
  const size_t n = static_cast<size_t>(width) * static_cast<size_t>(height);
  if (depth.size() != n) {
    return InvalidArgumentError("depth image " + std::to_string(width) + "x" + std::to_string(height) +
                                " holds " + std::to_string(depth.size()) + " depths");
  }
  if (!intensity.empty() && intensity.size() != n) {
    return InvalidArgumentError("depth image intensity holds " + std::to_string(intensity.size()) +
                                " values for " + std::to_string(n) + " pixels");
  }
  for (size_t i = 0; i < n; ++i) {
    if (depth[i] < 0.0f) {
      return InvalidArgumentError("depth image pixel (" + std::to_string(i % static_cast<size_t>(width)) + ", " +
                                  std::to_string(i / static_cast<size_t>(width)) + ") has negative depth " +
                                  std::to_string(depth[i]));
    }
  }
  return Status::Ok();
}

Expected<DepthImage> DepthImage::FromDisparity(std::span<const int16_t> disparity, int width, int height,
                                               double focal_px, double baseline, double disparity_offset_px) {
  DepthImage img;
  if (Status s = img.AssignDisparity(disparity, width, height, focal_px, baseline, disparity_offset_px);
      !s.ok())
    return s;
  return img;
}

Status DepthImage::AssignDisparity(std::span<const int16_t> disparity, int w, int h, double focal_px,
                                   double baseline, double disparity_offset_px) {
  if (w <= 0 || h <= 0 || disparity.size() != static_cast<size_t>(w) * static_cast<size_t>(h)) {
    return InvalidArgumentError("disparity image " + std::to_string(w) + "x" + std::to_string(h) + " holds " +
                                std::to_string(disparity.size()) + " values");
  }
  if (!(focal_px > 0.0) || !(baseline > 0.0)) {
    return InvalidArgumentError("disparity to depth needs positive focal length and baseline");
  }
  // Must match stereo/stereo_matcher_interface.h (kDisparityScale, kInvalidDisparity); mapping sits
  // below fpga in the dependency order, so the contract is restated here and tested there.
  constexpr double kScale = 16.0;
  constexpr int16_t kInvalid = std::numeric_limits<int16_t>::min();
  width = w;
  height = h;
  depth.resize(disparity.size());
  const double fb = focal_px * baseline;
  for (size_t i = 0; i < disparity.size(); ++i) {
    const int16_t d = disparity[i];
    if (d == kInvalid) {
      depth[i] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    const double dp = d / kScale + disparity_offset_px;
    depth[i] = dp > 0.0 ? static_cast<float>(fb / dp)
                        : (dp == 0.0 ? std::numeric_limits<float>::infinity()
                                     : std::numeric_limits<float>::quiet_NaN());
  }
  return Status::Ok();
}

}  // namespace cairn
