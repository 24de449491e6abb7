#include "estimation/vo/stereo_feature_tracker.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

#include <opencv2/features2d.hpp>
#include <opencv2/video/tracking.hpp>

namespace cairn {

StereoFeatureTracker::StereoFeatureTracker(const VoOptions& options, const RectifiedStereoCamera& camera)
    : options_(options),
      camera_(camera),
      window_(static_cast<int>(options.klt_window), static_cast<int>(options.klt_window)),
      // The right-image refinement starts within a pixel or two of the answer: a small window
      // keeps it local and cheap.
      stereo_window_(9, 9),
      criteria_(cv::TermCriteria::COUNT | cv::TermCriteria::EPS, static_cast<int>(options.klt_iterations), 0.001) {}

void StereoFeatureTracker::Prepare(const cv::Mat& left, const cv::Mat& right, StereoPyramids* pair) const {
  pair->left = left;
  pair->right = right;
  const int levels = static_cast<int>(options_.klt_levels);
  cv::buildOpticalFlowPyramid(left, pair->left_pyramid, window_, levels, true);
  // The right image is only searched near the predicted disparity: one level up is plenty.
  cv::buildOpticalFlowPyramid(right, pair->right_pyramid, stereo_window_, std::min(levels, 1), true);
}

int StereoFeatureTracker::SearchDisparity(const cv::Mat& left, const cv::Mat& right, int x, int y,
                                          double* subpixel) const {
  const int h = static_cast<int>(options_.stereo_patch / 2);
  const int max_d = std::min(static_cast<int>(options_.max_disparity), x - h);
  if (max_d < 1) return -1;
  // SAD over the patch for every disparity; best and runner-up outside the best's neighbours.
  int sad[513];
  for (int d = 0; d <= max_d; ++d) {
    int s = 0;
    for (int r = -h; r <= h; ++r) {
      const uint8_t* pl = left.ptr<uint8_t>(y + r) + x - h;
      const uint8_t* pr = right.ptr<uint8_t>(y + r) + x - h - d;
      for (int c = 0; c < 2 * h + 1; ++c) s += std::abs(static_cast<int>(pl[c]) - static_cast<int>(pr[c]));
    }
    sad[d] = s;
  }
  int best = 0;
  for (int d = 1; d <= max_d; ++d) {
    if (sad[d] < sad[best]) best = d;
  }
  int second = INT32_MAX;
  for (int d = 0; d <= max_d; ++d) {
    if (std::abs(d - best) > 1) second = std::min(second, sad[d]);
  }
  const int area = (2 * h + 1) * (2 * h + 1);
  if (sad[best] > options_.stereo_max_sad * area) return -1;
  if (second != INT32_MAX && sad[best] > options_.stereo_uniqueness * second) return -1;
  double off = 0.0;
  if (best > 0 && best < max_d) {
    const double a = sad[best - 1], b = sad[best], c = sad[best + 1];
    const double den = a - 2.0 * b + c;
    if (den > 0.0) off = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
  }
  *subpixel = best + off;
  return best;
}

void StereoFeatureTracker::MatchRight(const StereoPyramids& pair, double max_move, std::vector<uint8_t>* ok,
                                      std::vector<StereoObservation>* obs) {
  const size_t n = obs->size();
  a_.resize(n);
  b_.resize(n);
  for (size_t i = 0; i < n; ++i) {
    a_[i] = cv::Point2f(static_cast<float>((*obs)[i].u_left), static_cast<float>((*obs)[i].v));
    b_[i] = cv::Point2f(static_cast<float>((*obs)[i].u_right), static_cast<float>((*obs)[i].v));
  }
  if (n == 0) return;
  cv::calcOpticalFlowPyrLK(pair.left_pyramid, pair.right_pyramid, a_, b_, status_, err_, stereo_window_,
                           std::min<int>(1, static_cast<int>(pair.right_pyramid.size() / 2 - 1)), criteria_,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  for (size_t i = 0; i < n; ++i) {
    if (!(*ok)[i]) continue;
    const double row_error = std::abs(b_[i].y - a_[i].y);
    const double moved = std::abs(b_[i].x - (*obs)[i].u_right);
    if (!status_[i] || row_error > options_.max_row_error || moved > max_move ||
        b_[i].x < 0.0f || b_[i].x > static_cast<float>(pair.right.cols - 1)) {
      (*ok)[i] = 0;
      continue;
    }
    (*obs)[i].u_right = b_[i].x;
    (*obs)[i].v = 0.5 * (a_[i].y + b_[i].y);
    if ((*obs)[i].u_left - (*obs)[i].u_right < options_.min_disparity) (*ok)[i] = 0;
  }
}

void StereoFeatureTracker::DetectAndMatch(const StereoPyramids& pair, std::vector<StereoObservation>* observations) {
  observations->clear();
  const cv::Mat& left = pair.left;
  keypoints_.clear();
  cv::FAST(left, keypoints_, static_cast<int>(options_.fast_threshold), true);
  const int cols = static_cast<int>(options_.grid_cols), rows = static_cast<int>(options_.grid_rows);
  cells_.resize(static_cast<size_t>(cols * rows));
  for (auto& c : cells_) c.clear();
  const int border = static_cast<int>(std::max<int64_t>(options_.border, options_.stereo_patch / 2 + 1));
  for (size_t i = 0; i < keypoints_.size(); ++i) {
    const cv::Point2f& p = keypoints_[i].pt;
    if (p.x < border || p.y < border || p.x >= left.cols - border || p.y >= left.rows - border) continue;
    const int cx = std::min(cols - 1, static_cast<int>(p.x * cols / left.cols));
    const int cy = std::min(rows - 1, static_cast<int>(p.y * rows / left.rows));
    cells_[static_cast<size_t>(cy * cols + cx)].push_back(static_cast<int>(i));
  }
  // Strongest first in each cell; ties by position so the order never depends on the sort.
  const auto stronger = [&](int a, int b) {
    const cv::KeyPoint& ka = keypoints_[static_cast<size_t>(a)];
    const cv::KeyPoint& kb = keypoints_[static_cast<size_t>(b)];
    if (ka.response != kb.response) return ka.response > kb.response;
    if (ka.pt.y != kb.pt.y) return ka.pt.y < kb.pt.y;
    return ka.pt.x < kb.pt.x;
  };
  // An equal share per cell, taken from the strongest corners that find a stereo match.
  const size_t quota = static_cast<size_t>((options_.max_features + cols * rows - 1) / (cols * rows));
  ok_.clear();
  for (auto& c : cells_) {
    std::sort(c.begin(), c.end(), stronger);
    size_t taken = 0;
    for (size_t k = 0; k < c.size() && taken < quota; ++k) {
      const cv::Point2f& p = keypoints_[static_cast<size_t>(c[k])].pt;
      double d = 0.0;
      if (SearchDisparity(left, pair.right, static_cast<int>(p.x), static_cast<int>(p.y), &d) < 0) continue;
      observations->push_back(StereoObservation{p.x, p.x - d, p.y});
      ok_.push_back(1);
      ++taken;
    }
  }
  MatchRight(pair, 2.0, &ok_, observations);
  size_t w = 0;
  for (size_t i = 0; i < observations->size(); ++i) {
    if (ok_[i]) (*observations)[w++] = (*observations)[i];
  }
  observations->resize(std::min<size_t>(w, static_cast<size_t>(options_.max_features)));
}

void StereoFeatureTracker::Track(const StereoPyramids& kf, const std::vector<cv::Point2f>& kf_left,
                                 const std::vector<cv::Point2f>& predicted_left,
                                 const std::vector<float>& predicted_disparity, const StereoPyramids& cur,
                                 std::vector<StereoObservation>* out, std::vector<uint8_t>* found) {
  const size_t n = kf_left.size();
  out->assign(n, StereoObservation{});
  found->assign(n, 0);
  if (n == 0) return;
  c_ = predicted_left;
  const int levels = static_cast<int>(options_.klt_levels);
  cv::calcOpticalFlowPyrLK(kf.left_pyramid, cur.left_pyramid, kf_left, c_, status_, err_, window_, levels,
                           criteria_, cv::OPTFLOW_USE_INITIAL_FLOW);
  // Forward-backward check: tracking back must return to the keyframe corner.
  std::vector<cv::Point2f>& back = a_;
  back = kf_left;
  std::vector<uint8_t>& status_fwd = status_back_;
  status_fwd = status_;
  cv::calcOpticalFlowPyrLK(cur.left_pyramid, kf.left_pyramid, c_, back, status_, err_, window_, levels, criteria_,
                           cv::OPTFLOW_USE_INITIAL_FLOW);
  const float w = static_cast<float>(cur.left.cols - 1), h = static_cast<float>(cur.left.rows - 1);
  const double max_fb2 = options_.klt_max_fb_error * options_.klt_max_fb_error;
  for (size_t i = 0; i < n; ++i) {
    const cv::Point2f& p = c_[i];
    const cv::Point2f e = back[i] - kf_left[i];
    if (!status_fwd[i] || !status_[i] || p.x < 0.0f || p.y < 0.0f || p.x > w || p.y > h ||
        e.x * e.x + e.y * e.y > max_fb2) {
      continue;
    }
    (*found)[i] = 1;
    (*out)[i] = StereoObservation{p.x, p.x - std::max(0.0f, predicted_disparity[i]), p.y};
  }
  // The predicted disparity can be a few pixels off after larger motions.
  MatchRight(cur, 8.0, found, out);
}

}  // namespace cairn
