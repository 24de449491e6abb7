#include "detection/tag_detector.h"

#include <algorithm>
#include <cmath>
#include <string>

#include <apriltag/apriltag.h>
#include <apriltag/tag36h11.h>

namespace cairn {

Status TagDetectorOptions::Validate() const {
  for (const double id : ids) {
    if (id != std::floor(id) || id < 0.0 || id > 586.0)
      return InvalidArgumentError("tag detector: ids must be whole numbers in [0, 586], got " + std::to_string(id));
  }
  return Status::Ok();
}

TagDetector::TagDetector(const TagDetectorOptions& options)
    : options_(options), options_status_(options.Validate()) {
  family_ = tag36h11_create();
  detector_ = apriltag_detector_create();
  apriltag_detector_add_family_bits(detector_, family_, static_cast<int>(options_.max_corrected_bits));
  detector_->quad_decimate = static_cast<float>(options_.decimate);
  detector_->quad_sigma = static_cast<float>(options_.blur_sigma);
  detector_->refine_edges = options_.refine_edges;
  detector_->decode_sharpening = options_.sharpening;
  detector_->nthreads = static_cast<int>(options_.threads);
}

TagDetector::~TagDetector() {
  apriltag_detector_destroy(detector_);
  tag36h11_destroy(family_);
}

bool TagDetector::Accepts(int id) const {
  if (options_.ids.empty()) return true;
  return std::find(options_.ids.begin(), options_.ids.end(), static_cast<double>(id)) != options_.ids.end();
}

Expected<std::vector<TagDetection>> TagDetector::Detect(const Image& image, const PixelBox* roi) {
  if (!options_status_.ok()) return options_status_;
  ++counts_.images;
  const auto refuse = [&](const std::string& why) {
    ++counts_.bad_images;
    return InvalidArgumentError("tag detector: " + why);
  };
  if (image.empty()) return refuse("empty image");
  if (image.format != PixelFormat::kGray8) return refuse("needs an 8-bit gray image");
  if (image.stride < image.width) {
    return refuse("stride " + std::to_string(image.stride) + " shorter than a row of " +
                  std::to_string(image.width) + " px");
  }
  PixelBox box{0, 0, image.width, image.height};
  if (roi != nullptr) {
    box = *roi;
    if (box.x < 0 || box.y < 0 || box.width <= 0 || box.height <= 0 || box.x > image.width - box.width ||
        box.y > image.height - box.height) {
      return refuse("region " + std::to_string(box.width) + "x" + std::to_string(box.height) + "+" +
                    std::to_string(box.x) + "+" + std::to_string(box.y) + " not inside the " +
                    std::to_string(image.width) + "x" + std::to_string(image.height) + " image");
    }
  }
  // A view of the region: libapriltag reads the image and does not write to it.
  uint8_t* origin = const_cast<uint8_t*>(image.row(box.y)) + box.x;
  image_u8_t view{box.width, box.height, image.stride, origin};
  zarray_t* found = apriltag_detector_detect(detector_, &view);
  std::vector<TagDetection> out;
  for (int i = 0; i < zarray_size(found); ++i) {
    apriltag_detection_t* d = nullptr;
    zarray_get(found, i, &d);
    if (!Accepts(d->id)) {
      ++counts_.unknown_ids;
      continue;
    }
    if (!(d->decision_margin >= options_.min_decision_margin)) {
      ++counts_.low_margin;
      continue;
    }
    TagDetection t;
    t.id = d->id;
    t.hamming = d->hamming;
    t.decision_margin = d->decision_margin;
    t.decimate = options_.decimate;
    // libapriltag puts pixel centres at +0.5; the camera models put them at whole numbers.
    const double ox = box.x - 0.5, oy = box.y - 0.5;
    for (size_t c = 0; c < 4; ++c) {
      t.corners[c].x() = d->p[c][0] + ox;
      t.corners[c].y() = d->p[c][1] + oy;
    }
    t.center.x() = d->c[0] + ox;
    t.center.y() = d->c[1] + oy;
    out.push_back(t);
  }
  apriltag_detections_destroy(found);
  counts_.detections += out.size();
  std::sort(out.begin(), out.end(), [](const TagDetection& a, const TagDetection& b) {
    return a.id < b.id || (a.id == b.id && (a.center.y() < b.center.y() ||
                                            (a.center.y() == b.center.y() && a.center.x() < b.center.x())));
  });
  return out;
}

}  // namespace cairn
