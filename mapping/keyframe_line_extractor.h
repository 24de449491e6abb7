#pragma once
// One keyframe's straight edges in the left camera's frame: segments detected in the rectified left
// image, triangulated with the pair's disparity. Holds the detector's and the triangulator's
// scratch: after the first image of a size, Extract() allocates only when `out` must grow.
// Not thread safe (the mapping thread owns one).

#include <cstdint>
#include <vector>

#include "mapping/depth_image.h"
#include "mapping/line_options.h"
#include "mapping/line_sighting.h"

namespace cairn {

class KeyframeLineExtractor {
 public:
  KeyframeLineExtractor(const LineOptions& options, const StereoCamera& camera);

  struct Stats {
    int detected = 0;
    int triangulated = 0;
  };
  // Into `out` (cleared). False when the image or the disparity does not fit the camera.
  bool Extract(const uint8_t* left, int width, int height, int stride, const StereoMatcherOutput& disparity,
               std::vector<LineSighting>* out, Stats* stats = nullptr);

 private:
  LineSegmentDetector detector_;
  StereoLineTriangulator triangulator_;
  std::vector<ImageLineSegment> segments_;
  std::vector<StereoLineSegment> triangulated_;
};

}  // namespace cairn
