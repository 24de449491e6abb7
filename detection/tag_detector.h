#pragma once
// AprilTag 36h11 detection (libapriltag) on a gray image, over the whole frame or inside a region
// of interest around where a teammate or the lander is expected (thesis 6.2.1). Corners are in
// pixels of the full image with pixel centres at whole numbers (as PinholeRadTan and OpenCV; raw
// libapriltag output is half a pixel off from that), in libapriltag's order: counter-clockwise around the tag as the image
// shows it, starting at the corner the tag frame puts at (-1, +1) (see tag_pose_estimator.h).
//
// Bad input (an empty image, a colour image, a stride shorter than a row, a region outside the
// image) is a status, never a crash. Detections of ids that are not configured, and those whose
// decision margin is too low, are dropped and counted.

#include <array>
#include <cstdint>
#include <vector>

#include <Eigen/Core>

#include "common/options_visitor.h"
#include "common/status.h"
#include "hal/image.h"

struct apriltag_detector;
struct apriltag_family;

namespace cairn {

struct TagDetectorOptions {
  double decimate = 2.0;          // quads are found on an image this much smaller (1: full size)
  double blur_sigma = 0.0;        // px, Gaussian blur before quad finding (0: none)
  bool refine_edges = true;       // snap quad edges to the full-resolution gradients
  double sharpening = 0.25;       // of the decoded bits
  int64_t threads = 1;            // libapriltag's own worker threads
  int64_t max_corrected_bits = 2;  // bit errors corrected when decoding (of 11 the family allows)
  double min_decision_margin = 20.0;
  std::vector<double> ids;        // accepted tag ids; empty: every id of the family

  void Visit(OptionsVisitor& v) {
    v.Number("decimate", decimate, 1.0, 8.0, "");
    v.Number("blur_sigma", blur_sigma, 0.0, 5.0, "px");
    v.Flag("refine_edges", refine_edges);
    v.Number("sharpening", sharpening, 0.0, 1.0, "");
    v.Integer("threads", threads, 1, 16, "");
    v.Integer("max_corrected_bits", max_corrected_bits, 0, 3, "bits");
    v.Number("min_decision_margin", min_decision_margin, 0.0, 255.0, "");
    v.Numbers("ids", ids, 0, 587, 0.0, 586.0, "tag id");
  }
  Status Validate() const;
};

struct TagDetection {
  int id = -1;
  int hamming = 0;                // bits corrected
  double decision_margin = 0.0;
  std::array<Eigen::Vector2d, 4> corners;  // px, full image
  Eigen::Vector2d center = Eigen::Vector2d::Zero();
  double decimate = 1.0;  // of the detector that found it: its corners' accuracy depends on it
};

// Pixel rectangle [x, x + width) x [y, y + height).
struct PixelBox {
  int x = 0, y = 0, width = 0, height = 0;
};

struct TagDetectorCounts {
  uint64_t images = 0;
  uint64_t detections = 0;         // accepted
  uint64_t unknown_ids = 0;        // decoded, but not a configured id
  uint64_t low_margin = 0;         // decoded with a decision margin below the minimum
  uint64_t bad_images = 0;         // refused input
};

class TagDetector {
 public:
  // Options are checked by Validate(); invalid ones make every Detect() fail with the reason.
  explicit TagDetector(const TagDetectorOptions& options = {});
  ~TagDetector();
  TagDetector(const TagDetector&) = delete;
  TagDetector& operator=(const TagDetector&) = delete;

  // Tags in `image` (8-bit gray), or only inside `roi` when it is given.
  Expected<std::vector<TagDetection>> Detect(const Image& image, const PixelBox* roi = nullptr);

  const TagDetectorCounts& counts() const { return counts_; }

 private:
  bool Accepts(int id) const;

  TagDetectorOptions options_;
  Status options_status_;
  apriltag_detector* detector_ = nullptr;
  apriltag_family* family_ = nullptr;
  TagDetectorCounts counts_;
};

}  // namespace cairn
