#include "mapping/matching/plane_hypotheses.h"

#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include "mapping/testing/submap_faces.h"

namespace cairn {
namespace {

SubmapPlane Face(const Eigen::Vector3d& normal, const Eigen::Vector3d& centroid, double half_u,
                 double half_v) {
  SubmapPlane p = testing::FaceSeenFrom(Eigen::Isometry3d::Identity(), normal, centroid,
                                        Eigen::Vector2d(half_u, half_v), 0.0);
  p.points = static_cast<uint32_t>(p.area * 400);
  return p;
}

// The same face in frame B, where T_a_b maps B into A.
SubmapPlane InB(const SubmapPlane& a, const FourDofTransform& T_a_b) {
  const Eigen::Matrix3d R = T_a_b.rotation();
  const Eigen::Vector3d n = a.normal.cast<double>(), c = a.centroid.cast<double>();
  SubmapPlane b = a;
  b.normal = (R.transpose() * n).cast<float>();
  b.offset = static_cast<float>(a.offset + n.dot(T_a_b.translation()));
  b.centroid = (R.transpose() * (c - T_a_b.translation())).cast<float>();
  return b;
}

// The ground and two sides of a crate, as a rover in front of its corner sees them.
std::vector<SubmapPlane> CrateCorner() {
  return {Face({0, 0, 1}, {1.0, 0.5, 0.0}, 4.0, 3.0), Face({-1, 0, 0}, {3.0, 0.8, 0.6}, 1.0, 0.6),
          Face({0, -1, 0}, {3.8, 0.0, 0.6}, 0.8, 0.6)};
}

bool Contains(const std::vector<PlaneHypothesis>& hs, const FourDofTransform& truth) {
  for (const PlaneHypothesis& h : hs) {
    if ((h.T_a_b.translation() - truth.translation()).norm() < 0.01 &&
        std::abs(WrapAngle(h.T_a_b.yaw() - truth.yaw())) < 0.002)
      return true;
  }
  return false;
}

TEST(PlaneHypothesesTest, TwoSidesAndTheGroundGiveTheTransform) {
  const std::vector<SubmapPlane> a = CrateCorner();
  const FourDofTransform truth(1.7, -2.3, 0.4, 0.9);
  std::vector<SubmapPlane> b;
  for (const SubmapPlane& p : a) b.push_back(InB(p, truth));
  const std::vector<PlaneHypothesis> hs = PlaneHypotheses(PlaneHypothesisOptions{}).Find(a, b);
  ASSERT_FALSE(hs.empty());
  EXPECT_TRUE(Contains(hs, truth));
  EXPECT_LE(hs.size(), 8u);
}

TEST(PlaneHypothesesTest, AWallSeenFromItsOtherSideStillPairs) {
  std::vector<SubmapPlane> a = CrateCorner();
  const FourDofTransform truth(-3.0, 1.0, -0.2, -2.5);
  std::vector<SubmapPlane> b;
  for (const SubmapPlane& p : a) b.push_back(InB(p, truth));
  // B saw the first side from behind: its normal and offset turned over.
  b[1].normal = -b[1].normal;
  b[1].offset = -b[1].offset;
  EXPECT_TRUE(Contains(PlaneHypotheses(PlaneHypothesisOptions{}).Find(a, b), truth));
}

TEST(PlaneHypothesesTest, ParallelFacesOrFacesApartGiveNone) {
  // Two parallel walls fix no position along them.
  const std::vector<SubmapPlane> a = {Face({0, 0, 1}, {0, 0, 0}, 4, 4), Face({1, 0, 0}, {-2, 0, 1}, 2, 1),
                                      Face({-1, 0, 0}, {2, 0, 1}, 2, 1)};
  const FourDofTransform truth(0.5, 0.5, 0.0, 0.3);
  std::vector<SubmapPlane> b;
  for (const SubmapPlane& p : a) b.push_back(InB(p, truth));
  EXPECT_TRUE(PlaneHypotheses(PlaneHypothesisOptions{}).Find(a, b).empty());
  // The crate's sides, but B's are small and far from where A's are: no pairing lands on them.
  std::vector<SubmapPlane> c = CrateCorner();
  std::vector<SubmapPlane> d;
  for (const SubmapPlane& p : c) d.push_back(InB(p, truth));
  c[1].centroid.y() += 10.0f;  // A's first side elsewhere along itself
  PlaneHypothesisOptions o;
  o.extent_margin = 0.5;
  EXPECT_FALSE(Contains(PlaneHypotheses(o).Find(c, d), truth));
  o.enabled = false;
  EXPECT_TRUE(PlaneHypotheses(o).Find(CrateCorner(), d).empty());
}

}  // namespace
}  // namespace cairn
