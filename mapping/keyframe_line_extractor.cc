#include "mapping/keyframe_line_extractor.h"

namespace cairn {

KeyframeLineExtractor::KeyframeLineExtractor(const LineOptions& options, const StereoCamera& camera)
    : detector_(options.detection), triangulator_(options.triangulation, camera) {}

bool KeyframeLineExtractor::Extract(const uint8_t* left, int width, int height, int stride,
                                    const StereoMatcherOutput& disparity, std::vector<LineSighting>* out,
                                    Stats* stats) {
  out->clear();
  if (!detector_.Detect(left, width, height, stride, &segments_)) return false;
  if (!triangulator_.Triangulate(segments_, disparity, &triangulated_)) return false;
  for (const StereoLineSegment& t : triangulated_) {
    LineSighting s;
    s.a = t.p0;
    s.b = t.p1;
    s.cov_a = t.cov0;
    s.cov_b = t.cov1;
    s.cov_ab = t.cov01;
    out->push_back(s);  // viewpoint: the camera's centre, its frame's origin
  }
  if (stats != nullptr) {
    stats->detected = static_cast<int>(segments_.size());
    stats->triangulated = static_cast<int>(triangulated_.size());
  }
  return true;
}

}  // namespace cairn
