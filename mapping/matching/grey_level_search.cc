#include "mapping/matching/grey_level_search.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numbers>
#include <string>

#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "common/elapsed.h"

namespace cairn {
namespace {

// Rasters wider than this (cells per side) are refused: 205 m at the default cell, far beyond a
// submap; the FFTs' memory grows with its square.
constexpr int kMaxRasterCells = 2048;

// A cloud's finite points with finite grey levels, as flat arrays (filtered once, turned per yaw).
struct GreyPoints {
  std::vector<float> x, y, z, grey;
  GreyPoints(const std::vector<Eigen::Vector3d>& cloud, const std::vector<float>& g) {
    const size_t n = std::min(cloud.size(), g.size());
    for (size_t i = 0; i < n; ++i) {
      if (!cloud[i].allFinite() || !std::isfinite(g[i])) continue;
      x.push_back(static_cast<float>(cloud[i].x()));
      y.push_back(static_cast<float>(cloud[i].y()));
      z.push_back(static_cast<float>(cloud[i].z()));
      grey.push_back(g[i]);
    }
  }
  size_t size() const { return x.size(); }
};

// Grey levels (and heights) of points turned by a yaw, in cells of `cell` m from an origin: the
// local deviation of each textured cell's mean grey level (0 elsewhere), its square, the mask of
// those cells and their mean heights. The buffers are reused from one yaw to the next.
class Raster {
 public:
  Raster(int rows, int cols, double cell, int mean_half_width)
      : rows_(rows),
        cols_(cols),
        inverse_cell_(1.0 / cell),
        window_(2 * mean_half_width + 1, 2 * mean_half_width + 1) {
    for (cv::Mat* m : {&sum_, &count_, &z_, &mean_, &deviation, &deviation_sq, &mask, &height})
      m->create(rows, cols, CV_32F);
  }

  void Fill(const GreyPoints& points, double yaw, const Eigen::Vector2d& origin) {
    sum_.setTo(0.0f);
    count_.setTo(0.0f);
    z_.setTo(0.0f);
    const float c = static_cast<float>(std::cos(yaw)), s = static_cast<float>(std::sin(yaw));
    const float ox = static_cast<float>(origin.x()), oy = static_cast<float>(origin.y());
    const float inv = static_cast<float>(inverse_cell_);
    float* sum = sum_.ptr<float>();
    float* count = count_.ptr<float>();
    float* z = z_.ptr<float>();
    const float cols = static_cast<float>(cols_), rows = static_cast<float>(rows_);
    for (size_t i = 0; i < points.size(); ++i) {
      const float fc = (c * points.x[i] - s * points.y[i] - ox) * inv;
      const float fr = (s * points.x[i] + c * points.y[i] - oy) * inv;
      // Only cells from 0 on are kept, where truncation is the floor (a library call per point
      // otherwise, on the search's hottest loop); the test also rejects NaN.
      if (!(fc >= 0.0f && fr >= 0.0f && fc < cols && fr < rows)) continue;
      const size_t k = static_cast<size_t>(fr) * static_cast<size_t>(cols_) + static_cast<size_t>(fc);
      sum[k] += points.grey[i];
      count[k] += 1.0f;
      z[k] += points.z[i];
    }
    const size_t n = static_cast<size_t>(rows_) * static_cast<size_t>(cols_);
    float* m = mask.ptr<float>();
    float* mean = mean_.ptr<float>();
    float* h = height.ptr<float>();
    for (size_t k = 0; k < n; ++k) {
      const bool known = count[k] > 0.0f;
      m[k] = known ? 1.0f : 0.0f;
      mean[k] = known ? sum[k] / count[k] : 0.0f;
      h[k] = known ? z[k] / count[k] : 0.0f;
    }
    // Local mean over the textured cells of the window (sum_ and count_ are free again).
    cv::boxFilter(mean_, sum_, CV_32F, window_, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    cv::boxFilter(mask, count_, CV_32F, window_, cv::Point(-1, -1), false, cv::BORDER_CONSTANT);
    float* d = deviation.ptr<float>();
    float* d2 = deviation_sq.ptr<float>();
    for (size_t k = 0; k < n; ++k) {
      d[k] = m[k] != 0.0f ? mean[k] - sum[k] / count[k] : 0.0f;
      d2[k] = d[k] * d[k];
    }
  }

  cv::Mat deviation, deviation_sq, mask, height;  // CV_32F

 private:
  int rows_, cols_;
  double inverse_cell_;
  cv::Size window_;
  cv::Mat sum_, count_, z_, mean_;
};

// Forward DFTs (packed) of rasters placed at the top left of a zero matrix of the padded size,
// and correlations of two spectra, with buffers reused from one yaw to the next.
class Spectra {
 public:
  Spectra(int rows, int cols) : padded_(cv::Mat::zeros(rows, cols, CV_32F)) {}
  void Forward(const cv::Mat& m, cv::Mat& spectrum) {
    m.copyTo(padded_(cv::Rect(0, 0, m.cols, m.rows)));
    cv::dft(padded_, spectrum, 0, m.rows);
  }
  // sum_x a(x + s) b(x) for every circular shift s.
  void Correlate(const cv::Mat& spectrum_a, const cv::Mat& spectrum_b, cv::Mat& out) {
    cv::mulSpectrums(spectrum_a, spectrum_b, product_, 0, true);
    cv::idft(product_, out, cv::DFT_SCALE | cv::DFT_REAL_OUTPUT);
  }

 private:
  cv::Mat padded_, product_;
};

struct SearchPeak {
  double yaw = 0.0;
  Eigen::Vector2d shift;  // cells, sub-cell refined
  double correlation = 0.0;
  int64_t overlap = 0;
  Eigen::Vector2d t_xy;
};

}  // namespace

Eigen::Vector2d GreyLevelSearch::SearchSlack(const std::vector<Eigen::Vector3d>& cloud_b) const {
  const double half_step = std::numbers::pi / std::ceil(2.0 * std::numbers::pi / options_.yaw_step);
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  size_t n = 0;
  for (const Eigen::Vector3d& p : cloud_b) {
    if (!p.allFinite()) continue;
    centroid += p.head<2>();
    ++n;
  }
  const double lever = n > 0 ? centroid.norm() / static_cast<double>(n) : 0.0;
  return {0.5 * std::numbers::sqrt2 * options_.cell + lever * half_step, half_step};
}

Expected<GreyLevelSearchResult> GreyLevelSearch::Search(const std::vector<Eigen::Vector3d>& cloud_a,
                                                        const std::vector<float>& grey_a,
                                                        const std::vector<Eigen::Vector3d>& cloud_b,
                                                        const std::vector<float>& grey_b,
                                                        Eigen::Vector2d yaw_window) const {
  const auto start = std::chrono::steady_clock::now();
  const GreyLevelSearchOptions& o = options_;
  if (!(o.cell > 0.0) || !(o.yaw_step > 0.0) || o.max_candidates < 1)
    return InvalidArgumentError("grey-level search: cell and yaw_step must be > 0, max_candidates >= 1");
  GreyLevelSearchResult out;

  // A's raster over its points' xy box; B's turned about its box centre within a square that
  // holds it at every yaw.
  const GreyPoints points_a(cloud_a, grey_a), points_b(cloud_b, grey_b);
  Eigen::AlignedBox2d box_a, box_b;
  for (size_t i = 0; i < points_a.size(); ++i) box_a.extend(Eigen::Vector2d(points_a.x[i], points_a.y[i]));
  for (size_t i = 0; i < points_b.size(); ++i) box_b.extend(Eigen::Vector2d(points_b.x[i], points_b.y[i]));
  if (box_a.isEmpty() || box_b.isEmpty()) {
    out.ms = MillisecondsSince(start);
    return out;
  }
  const Eigen::Vector2d centre_b = box_b.center();
  double radius_b = 0.0;
  for (size_t i = 0; i < points_b.size(); ++i)
    radius_b = std::max(radius_b, (Eigen::Vector2d(points_b.x[i], points_b.y[i]) - centre_b).norm());
  const int cols_a = static_cast<int>(std::ceil(box_a.sizes().x() / o.cell)) + 1;
  const int rows_a = static_cast<int>(std::ceil(box_a.sizes().y() / o.cell)) + 1;
  const int side_b = static_cast<int>(std::ceil(2.0 * radius_b / o.cell)) + 1;
  if (std::max({cols_a, rows_a, side_b}) > kMaxRasterCells)
    return InvalidArgumentError("grey-level search: a raster of " +
                                std::to_string(std::max({cols_a, rows_a, side_b})) +
                                " cells per side, more than " + std::to_string(kMaxRasterCells));
  const int half_width = static_cast<int>(std::lround(o.local_mean_radius / o.cell));
  const Eigen::Vector2d origin_a = box_a.min();
  Raster ra(rows_a, cols_a, o.cell, half_width);
  ra.Fill(points_a, 0.0, origin_a);

  // Linear (not circular) correlation: every shift from -(side_b - 1) to size_a - 1.
  const int rows = cv::getOptimalDFTSize(rows_a + side_b - 1),
            cols = cv::getOptimalDFTSize(cols_a + side_b - 1);
  cv::Mat fa, fa_sq, fa_mask;
  {
    Spectra spectra_a(rows, cols);
    spectra_a.Forward(ra.deviation, fa);
    spectra_a.Forward(ra.deviation_sq, fa_sq);
    spectra_a.Forward(ra.mask, fa_mask);
  }
  Spectra spectra(rows, cols);
  Raster rb(side_b, side_b, o.cell, half_width);
  cv::Mat fb, fb_sq, fb_mask, overlap, ab, aa, bb;

  const int yaws = static_cast<int>(std::ceil(2.0 * std::numbers::pi / o.yaw_step));
  const double step = 2.0 * std::numbers::pi / yaws;
  const int suppress = std::max(1, static_cast<int>(std::ceil(o.separation_translation / o.cell)));
  std::vector<SearchPeak> peaks;
  cv::Mat score(rows, cols, CV_32F);
  // A window's yaws are stepped from its centre, so that a narrow one (a relative estimate the
  // graph knows well) searches that yaw itself rather than the grid's nearest, up to half a step off.
  const bool windowed = yaw_window.y() < std::numbers::pi;
  for (int k = 0; k < yaws; ++k) {
    const double yaw =
        windowed ? WrapAngle(yaw_window.x() + step * (k - yaws / 2)) : -std::numbers::pi + step * k;
    if (std::abs(WrapAngle(yaw - yaw_window.x())) > yaw_window.y() + 0.5 * step) continue;
    ++out.yaws;
    const Eigen::Vector2d turned_centre = Eigen::Rotation2Dd(yaw) * centre_b;
    const Eigen::Vector2d origin_b = turned_centre - Eigen::Vector2d::Constant(radius_b);
    rb.Fill(points_b, yaw, origin_b);
    spectra.Forward(rb.deviation, fb);
    spectra.Forward(rb.deviation_sq, fb_sq);
    spectra.Forward(rb.mask, fb_mask);
    spectra.Correlate(fa_mask, fb_mask, overlap);
    spectra.Correlate(fa, fb, ab);
    spectra.Correlate(fa_sq, fb_mask, aa);
    spectra.Correlate(fa_mask, fb_sq, bb);
    {
      const size_t n = static_cast<size_t>(rows) * static_cast<size_t>(cols);
      const float* ov = overlap.ptr<float>();
      const float* pab = ab.ptr<float>();
      const float* paa = aa.ptr<float>();
      const float* pbb = bb.ptr<float>();
      float* ps = score.ptr<float>();
      const float min_overlap = static_cast<float>(o.min_overlap_cells) - 0.5f;
      for (size_t i = 0; i < n; ++i) {
        const double d = static_cast<double>(paa[i]) * pbb[i];
        ps[i] = ov[i] >= min_overlap && d > 1e-12 ? static_cast<float>(pab[i] / std::sqrt(d)) : -2.0f;
      }
    }
    // The best few peaks of this yaw, each suppressing its neighbourhood.
    for (int64_t taken = 0; taken < o.max_candidates; ++taken) {
      double best = 0.0;
      cv::Point at;
      cv::minMaxLoc(score, nullptr, &best, nullptr, &at);
      if (best < o.min_correlation) break;
      SearchPeak p;
      p.yaw = yaw;
      p.correlation = best;
      p.overlap = static_cast<int64_t>(std::lround(overlap.at<float>(at)));
      // Sub-cell position by a parabola through the neighbours (circular indices).
      const auto value = [&](int r, int c) {
        return static_cast<double>(score.at<float>((r + rows) % rows, (c + cols) % cols));
      };
      const auto vertex = [](double left, double mid, double right) {
        const double den = left - 2.0 * mid + right;
        return left > -1.5 && right > -1.5 && den < 0.0 ? std::clamp(0.5 * (left - right) / den, -0.5, 0.5)
                                                        : 0.0;
      };
      const double dc = vertex(value(at.y, at.x - 1), best, value(at.y, at.x + 1));
      const double dr = vertex(value(at.y - 1, at.x), best, value(at.y + 1, at.x));
      const int sr = at.y <= rows_a - 1 ? at.y : at.y - rows;
      const int sc = at.x <= cols_a - 1 ? at.x : at.x - cols;
      p.shift = Eigen::Vector2d(sc + dc, sr + dr);
      p.t_xy = origin_a + o.cell * p.shift - origin_b;
      peaks.push_back(p);
      for (int r = at.y - suppress; r <= at.y + suppress; ++r)
        for (int c = at.x - suppress; c <= at.x + suppress; ++c)
          score.at<float>((r + rows) % rows, (c + cols) % cols) = -2.0f;
    }
  }

  std::stable_sort(peaks.begin(), peaks.end(),
                   [](const SearchPeak& x, const SearchPeak& y) { return x.correlation > y.correlation; });
  std::vector<SearchPeak> kept;
  for (const SearchPeak& p : peaks) {
    if (static_cast<int64_t>(kept.size()) >= o.max_candidates) break;
    bool same = false;
    for (const SearchPeak& q : kept) {
      same = same || ((p.t_xy - q.t_xy).norm() < o.separation_translation &&
                      std::abs(WrapAngle(p.yaw - q.yaw)) < o.separation_yaw);
    }
    if (!same) kept.push_back(p);
  }

  // z: the median height difference over the cells both rasters hold.
  std::vector<float> dz;
  for (const SearchPeak& p : kept) {
    const Eigen::Vector2d turned_centre = Eigen::Rotation2Dd(p.yaw) * centre_b;
    const Eigen::Vector2d origin_b = turned_centre - Eigen::Vector2d::Constant(radius_b);
    rb.Fill(points_b, p.yaw, origin_b);
    const int sr = static_cast<int>(std::lround(p.shift.y())),
              sc = static_cast<int>(std::lround(p.shift.x()));
    dz.clear();
    for (int r = 0; r < side_b; ++r) {
      for (int c = 0; c < side_b; ++c) {
        const int ar = r + sr, ac = c + sc;
        if (rb.mask.at<float>(r, c) == 0.0f || ar < 0 || ac < 0 || ar >= rows_a || ac >= cols_a ||
            ra.mask.at<float>(ar, ac) == 0.0f)
          continue;
        dz.push_back(ra.height.at<float>(ar, ac) - rb.height.at<float>(r, c));
      }
    }
    if (dz.empty()) continue;
    std::nth_element(dz.begin(), dz.begin() + static_cast<ptrdiff_t>(dz.size() / 2), dz.end());
    GreyLevelCandidate candidate;
    candidate.T_a_b = FourDofTransform(p.t_xy.x(), p.t_xy.y(), dz[dz.size() / 2], p.yaw);
    candidate.correlation = p.correlation;
    candidate.overlap_cells = p.overlap;
    out.candidates.push_back(candidate);
  }
  out.ms = MillisecondsSince(start);
  return out;
}

}  // namespace cairn
