#pragma once
// Image side of the stereo visual odometry: corners spread over the rectified left image
// (bucketed FAST), their sub-pixel match in the right image (row search, then Lucas-Kanade),
// and pyramidal Lucas-Kanade tracking of a keyframe's corners into a later pair.
//
// Buffers (pyramids, point lists) live in the caller's StereoPyramids and are reused from frame
// to frame, so a steady stream of equally sized images does not reallocate them.

#include <cstdint>
#include <vector>

#include <opencv2/core.hpp>

#include "estimation/vo/vo_options.h"
#include "estimation/vo/vo_types.h"

namespace cairn {

// Both images of one rectified pair with their Lucas-Kanade pyramids.
struct StereoPyramids {
  cv::Mat left, right;  // level 0 (views of the caller's pixels, valid while it keeps them)
  std::vector<cv::Mat> left_pyramid, right_pyramid;
};

class StereoFeatureTracker {
 public:
  StereoFeatureTracker(const VoOptions& options, const RectifiedStereoCamera& camera);

  // Builds both pyramids.
  void Prepare(const cv::Mat& left, const cv::Mat& right, StereoPyramids* pair) const;

  // Detects corners in the left image and matches them in the right one. Returns the stereo
  // observations of the corners that found a unique, sub-pixel match.
  void DetectAndMatch(const StereoPyramids& pair, std::vector<StereoObservation>* observations);

  // Tracks `kf_left` (left-image pixels in the keyframe) into `cur`, starting from
  // `predicted_left`, then finds each track in the current right image starting from
  // `predicted_disparity`. `found[i]` says whether observation `out[i]` is valid.
  void Track(const StereoPyramids& kf, const std::vector<cv::Point2f>& kf_left,
             const std::vector<cv::Point2f>& predicted_left, const std::vector<float>& predicted_disparity,
             const StereoPyramids& cur, std::vector<StereoObservation>* out, std::vector<uint8_t>* found);

 private:
  // Integer disparity by a row search of the patch around (x, y); -1 when none is unique.
  int SearchDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y, double* subpixel) const;
  // Lucas-Kanade of left-image points into the right image (level 0..1), checked against the
  // rectified geometry. Writes u_right and the mean row, clears `ok` where it fails.
  // `max_move` bounds the refinement's distance from the initial guess (px).
  void MatchRight(const StereoPyramids& pair, double max_move, std::vector<uint8_t>* ok,
                  std::vector<StereoObservation>* obs);

  VoOptions options_;
  RectifiedStereoCamera camera_;
  cv::Size window_, stereo_window_;
  cv::TermCriteria criteria_;
  // Scratch, reused.
  std::vector<cv::KeyPoint> keypoints_;
  std::vector<std::vector<int>> cells_;
  std::vector<cv::Point2f> a_, b_, c_;
  std::vector<uint8_t> status_, status_back_, ok_;
  std::vector<float> err_;
};

}  // namespace cairn
