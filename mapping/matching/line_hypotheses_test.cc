#include "mapping/matching/line_hypotheses.h"

#include <cmath>

#include <gtest/gtest.h>

namespace cairn {
namespace {

SubmapLine LineThrough(const Eigen::Vector3d& a, const Eigen::Vector3d& b, const Eigen::Vector3d& anchor) {
  SubmapLine l;
  const Eigen::Vector3d d = (b - a).normalized();
  l.anchor = anchor.cast<float>();
  l.direction = d.cast<float>();
  l.moment = ((a - anchor).cross(d)).cast<float>();
  const Eigen::Vector3d closest = l.ClosestPoint().cast<double>();
  l.t_min = static_cast<float>(std::min(d.dot(a - closest), d.dot(b - closest)));
  l.t_max = static_cast<float>(std::max(d.dot(a - closest), d.dot(b - closest)));
  return l;
}

// A crate's edges (1.5 x 1.2 x 1 m at (3, 1)) and a wall's top, in a submap frame.
std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> LineHypothesesTestScene() {
  const Eigen::Vector3d c(3.0, 1.0, 0.0);
  return {{c, c + Eigen::Vector3d(0, 0, 1.0)},
          {c + Eigen::Vector3d(1.5, 0, 0), c + Eigen::Vector3d(1.5, 0, 1.0)},
          {c + Eigen::Vector3d(0, 0, 1.0), c + Eigen::Vector3d(1.5, 0, 1.0)},
          {c + Eigen::Vector3d(0, 0, 1.0), c + Eigen::Vector3d(0, 1.2, 1.0)},
          {Eigen::Vector3d(-2, 4, 2.0), Eigen::Vector3d(2, 6, 2.0)}};
}

std::vector<SubmapLine> LinesSeenFrom(const Eigen::Isometry3d& T_frame_world, double keep) {
  std::vector<SubmapLine> out;
  for (const auto& [a, b] : LineHypothesesTestScene()) {
    // Each sees a part of every edge.
    const Eigen::Vector3d a2 = a + (1.0 - keep) * (b - a);
    out.push_back(LineThrough(T_frame_world * a2, T_frame_world * b, Eigen::Vector3d::Zero()));
  }
  return out;
}

const Eigen::Vector3d kLineTestOrigin = Eigen::Vector3d::Zero();

bool LineHypothesesTestFound(const std::vector<LineHypothesis>& found, const FourDofTransform& truth) {
  for (const LineHypothesis& h : found) {
    // Edges are stored in float.
    if ((h.T_a_b.translation() - truth.translation()).norm() < 1e-3 &&
        std::abs(std::remainder(h.T_a_b.yaw() - truth.yaw(), 2.0 * M_PI)) < 1e-4)
      return true;
  }
  return false;
}

TEST(LineHypothesesTest, EdgesSeenByTwoRobotsGiveTheirTransform) {
  const FourDofTransform T_a_b(2.0, -1.0, 0.3, 0.7);
  const Eigen::Isometry3d T_a_world = Eigen::Isometry3d::Identity();
  const Eigen::Isometry3d T_b_world = T_a_b.ToIsometry().inverse() * T_a_world;
  LineHypothesisOptions options;
  const auto found =
      LineHypotheses(options).Find(LinesSeenFrom(T_a_world, 1.0), LinesSeenFrom(T_b_world, 0.7));
  ASSERT_FALSE(found.empty());
  EXPECT_LE(found.size(), static_cast<size_t>(options.max_hypotheses));
  // The right one first: all five edges agree with it, the crate's look-alike corners with fewer.
  EXPECT_TRUE(LineHypothesesTestFound({found.front()}, T_a_b));
  EXPECT_EQ(found.front().edges_agreeing, 5);
}

TEST(LineHypothesesTest, TwoVerticalEdgesAloneGiveTheTransform) {
  const FourDofTransform T_a_b(-1.0, 2.5, 0.0, -2.0);
  const Eigen::Isometry3d T_b_a = T_a_b.ToIsometry().inverse();
  const auto scene = LineHypothesesTestScene();
  std::vector<SubmapLine> a, b;
  for (int k = 0; k < 2; ++k) {
    a.push_back(LineThrough(scene[static_cast<size_t>(k)].first, scene[static_cast<size_t>(k)].second,
                            kLineTestOrigin));
    b.push_back(LineThrough(T_b_a * scene[static_cast<size_t>(k)].first,
                            T_b_a * scene[static_cast<size_t>(k)].second, kLineTestOrigin));
  }
  LineHypothesisOptions options;
  options.min_pair_angle = 1.0;
  // Parallel: no pair at 20 deg.
  EXPECT_TRUE(LineHypotheses(LineHypothesisOptions{}).Find(a, b).empty());
  // Two parallel vertical edges have an angle of 0: pairs need one; a vertical edge and the
  // crate's top give it.
  a.push_back(LineThrough(scene[2].first, scene[2].second, kLineTestOrigin));
  b.push_back(LineThrough(T_b_a * scene[2].first, T_b_a * scene[2].second, kLineTestOrigin));
  EXPECT_TRUE(LineHypothesesTestFound(LineHypotheses(LineHypothesisOptions{}).Find(a, b), T_a_b));
}

TEST(LineHypothesesTest, OtherGeometryGivesNothing) {
  const auto scene = LineHypothesesTestScene();
  std::vector<SubmapLine> a, b;
  for (const auto& [p, q] : scene) a.push_back(LineThrough(p, q, kLineTestOrigin));
  // B: two level edges 45 deg apart, one 0.5 m above the other: A's level pairs are 26.6, 63.4 and
  // 90 deg apart, 0 or 1 m above each other.
  b.push_back(LineThrough(Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(2, 0, 0), kLineTestOrigin));
  b.push_back(LineThrough(Eigen::Vector3d(0, 1, 0.5), Eigen::Vector3d(2, 3, 0.5), kLineTestOrigin));
  EXPECT_TRUE(LineHypotheses(LineHypothesisOptions{}).Find(a, b).empty());
  // Disabled, and edges too short.
  LineHypothesisOptions off;
  off.enabled = false;
  EXPECT_TRUE(LineHypotheses(off).Find(a, a).empty());
  LineHypothesisOptions long_only;
  long_only.min_length = 10.0;
  EXPECT_TRUE(LineHypotheses(long_only).Find(a, a).empty());
  EXPECT_FALSE(LineHypotheses(LineHypothesisOptions{}).Find(a, a).empty());
}

}  // namespace
}  // namespace cairn
