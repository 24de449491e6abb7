#include "mapping/matching/submap_suitability.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

namespace cairn {
namespace {

// Keypoints farther than `distance` from the line through `p` along the unit vector `d` (xy).
int64_t CountOffLine(const std::vector<Eigen::Vector2d>& xy, const Eigen::Vector2d& p,
                     const Eigen::Vector2d& d, double distance) {
  int64_t off = 0;
  for (const Eigen::Vector2d& q : xy) {
    const Eigen::Vector2d e = q - p;
    if (std::abs(e.x() * d.y() - e.y() * d.x()) > distance) ++off;
  }
  return off;
}

// Least-squares line (centroid, principal direction) of the keypoints within `distance` of a line.
bool RefitLine(const std::vector<Eigen::Vector2d>& xy, const Eigen::Vector2d& p, const Eigen::Vector2d& d,
               double distance, Eigen::Vector2d* p_fit, Eigen::Vector2d* d_fit) {
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  std::vector<const Eigen::Vector2d*> inliers;
  for (const Eigen::Vector2d& q : xy) {
    const Eigen::Vector2d e = q - p;
    if (std::abs(e.x() * d.y() - e.y() * d.x()) <= distance) {
      inliers.push_back(&q);
      sum += q;
    }
  }
  if (inliers.size() < 2) return false;
  const Eigen::Vector2d mean = sum / static_cast<double>(inliers.size());
  double sxx = 0, sxy = 0, syy = 0;
  for (const Eigen::Vector2d* q : inliers) {
    const Eigen::Vector2d e = *q - mean;
    sxx += e.x() * e.x();
    sxy += e.x() * e.y();
    syy += e.y() * e.y();
  }
  if (sxx + syy <= 0.0) return false;
  const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
  *p_fit = mean;
  *d_fit = Eigen::Vector2d(std::cos(angle), std::sin(angle));
  return true;
}

}  // namespace

std::string_view SuitabilityReasonName(SuitabilityReason reason) {
  switch (reason) {
    case SuitabilityReason::kSuitable:
      return "suitable";
    case SuitabilityReason::kTooFewPoints:
      return "too few points";
    case SuitabilityReason::kTooFewObstaclePoints:
      return "too few obstacle points";
    case SuitabilityReason::kTooFewKeypoints:
      return "too few keypoints";
    case SuitabilityReason::kKeypointsOnLine:
      return "keypoints on a line";
  }
  return "unknown";
}

SuitabilityResult SubmapSuitability::CheckCloud(const std::vector<CloudPoint>& points) const {
  SuitabilityResult r;
  for (const CloudPoint& c : points) {
    if (!c.p.allFinite()) {
      ++r.non_finite_points;
      continue;
    }
    ++r.points;
    if (c.obstacle) ++r.obstacle_points;
  }
  std::ostringstream m;
  if (r.points < options_.min_points) {
    r.reason = SuitabilityReason::kTooFewPoints;
    m << r.points << " points, fewer than " << options_.min_points;
  } else if (r.obstacle_points < options_.min_obstacle_points) {
    r.reason = SuitabilityReason::kTooFewObstaclePoints;
    m << r.obstacle_points << " obstacle points, fewer than " << options_.min_obstacle_points;
  } else {
    m << r.points << " points, " << r.obstacle_points << " obstacle points";
  }
  if (r.non_finite_points > 0) m << " (" << r.non_finite_points << " non-finite points skipped)";
  r.message = m.str();
  return r;
}

int64_t SubmapSuitability::OffLineKeypoints(const std::vector<Eigen::Vector3f>& keypoints) const {
  std::vector<Eigen::Vector2d> xy;
  xy.reserve(keypoints.size());
  for (const Eigen::Vector3f& k : keypoints) {
    if (k.allFinite()) xy.emplace_back(k.x(), k.y());
  }
  const size_t n = xy.size();
  if (n == 0) return 0;
  const double dist = options_.off_line_distance;
  // Without two distinct points in xy every line through the one spot fits.
  int64_t best = CountOffLine(xy, xy[0], Eigen::Vector2d::UnitX(), dist);
  best = std::min(best, CountOffLine(xy, xy[0], Eigen::Vector2d::UnitY(), dist));
  auto try_pair = [&](size_t i, size_t j) {
    const Eigen::Vector2d d = xy[j] - xy[i];
    const double len = d.norm();
    if (len < 1e-9) return;
    const Eigen::Vector2d u = d / len;
    best = std::min(best, CountOffLine(xy, xy[i], u, dist));
    Eigen::Vector2d p_fit, d_fit;
    if (RefitLine(xy, xy[i], u, dist, &p_fit, &d_fit))
      best = std::min(best, CountOffLine(xy, p_fit, d_fit, dist));
  };
  const uint64_t pairs = static_cast<uint64_t>(n) * (n - 1) / 2;
  const uint64_t samples = static_cast<uint64_t>(std::max<int64_t>(1, options_.line_samples));
  if (pairs <= samples) {
    for (size_t i = 0; i < n; ++i) {
      for (size_t j = i + 1; j < n; ++j) try_pair(i, j);
    }
  } else {
    std::mt19937 rng(options_.seed);
    std::uniform_int_distribution<size_t> pick(0, n - 1);
    for (uint64_t s = 0; s < samples; ++s) {
      const size_t i = pick(rng), j = pick(rng);
      if (i != j) try_pair(i, j);
    }
  }
  return best;
}

SuitabilityResult SubmapSuitability::CheckKeypoints(const std::vector<Eigen::Vector3f>& keypoints) const {
  SuitabilityResult r;
  for (const Eigen::Vector3f& k : keypoints) r.keypoints += k.allFinite() ? 1 : 0;
  std::ostringstream m;
  if (r.keypoints < options_.min_off_line_keypoints) {
    r.reason = SuitabilityReason::kTooFewKeypoints;
    m << r.keypoints << " keypoints, fewer than the " << options_.min_off_line_keypoints
      << " that must lie off a line";
  } else {
    r.off_line_keypoints = OffLineKeypoints(keypoints);
    if (r.off_line_keypoints < options_.min_off_line_keypoints) {
      r.reason = SuitabilityReason::kKeypointsOnLine;
      m << "only " << r.off_line_keypoints << " of " << r.keypoints << " keypoints farther than "
        << options_.off_line_distance << " m from a line in xy, fewer than "
        << options_.min_off_line_keypoints;
    } else {
      m << r.off_line_keypoints << " of " << r.keypoints << " keypoints farther than "
        << options_.off_line_distance << " m from the best line in xy";
    }
  }
  r.message = m.str();
  return r;
}

SuitabilityResult SubmapSuitability::Check(const Submap& submap,
                                           const std::vector<Eigen::Vector3f>& keypoints) const {
  SuitabilityResult cloud = CheckCloud(submap.points());
  if (!cloud.suitable()) return cloud;
  SuitabilityResult r = CheckKeypoints(keypoints);
  r.points = cloud.points;
  r.obstacle_points = cloud.obstacle_points;
  r.non_finite_points = cloud.non_finite_points;
  r.message = cloud.message + "; " + r.message;
  return r;
}

}  // namespace cairn
