#pragma once
// `mapping.lines`: straight edges of the keyframes (paper 000's line segments), detected in the left
// image, triangulated with the dense disparity and joined per submap into anchored Pluecker lines.

#include "common/options_visitor.h"
#include "mapping/line_segment_detector.h"
#include "mapping/stereo_line_triangulator.h"
#include "mapping/submap_line_fuser.h"

namespace cairn {

struct LineOptions {
  bool enabled = true;
  LineSegmentOptions detection;
  StereoLineOptions triangulation;
  LineFusionOptions fusion;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Section("detection", detection);
    v.Section("triangulation", triangulation);
    v.Section("fusion", fusion);
  }
};

}  // namespace cairn
