#include "mapping/matching/plane_associator.h"

#include <gtest/gtest.h>

#include "estimation/math/so3.h"
#include "mapping/matching/testing/placements.h"
#include "mapping/testing/submap_faces.h"

namespace cairn {
namespace {

using testing::PlacedWithSigma;
using testing::YawedPose;

struct FacesWorld {
  Eigen::Isometry3d a = YawedPose(0.0, 0.0, 0.0), b = YawedPose(4.0, 1.0, 0.6);
  // Walls and a tilted panel; a level ground and a small crate face that are no landmarks.
  std::vector<std::pair<Eigen::Vector3d, Eigen::Vector3d>> faces = {
      {Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(8, 1, 1)},
      {Eigen::Vector3d(0, -1, 0), Eigen::Vector3d(3, 6, 1)},
      {Eigen::Vector3d(0.5, 0.5, 0.7), Eigen::Vector3d(2, -3, 0.5)},
      {Eigen::Vector3d(0, 0, 1), Eigen::Vector3d(2, 0, -1)}};
  std::vector<SubmapPlane> Seen(const Eigen::Isometry3d& T) const {
    std::vector<SubmapPlane> out;
    for (const auto& [n, c] : faces) out.push_back(testing::FaceSeenFrom(T, n, c));
    out.push_back(testing::FaceSeenFrom(T, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 3, 0.2),
                                        Eigen::Vector2d(0.3, 0.3)));
    return out;
  }
};

TEST(PlaneAssociatorTest, PairsTheSameSteepFacesOnly) {
  const FacesWorld w;
  const PlaneAssociator associator{PlaneAssociationOptions{}};
  // B's origin off by 0.2 m and 1 deg in the graph, with a covariance that covers it.
  const Eigen::Isometry3d b_estimate = YawedPose(4.2, 0.9, 0.6 + 0.017);
  const auto pairs = associator.Associate(w.Seen(w.a), PlacedWithSigma(w.a, 0.01, 0.001), w.Seen(w.b),
                                          PlacedWithSigma(b_estimate, 0.3, 0.03));
  ASSERT_EQ(pairs.size(), 3u);
  for (int k = 0; k < 3; ++k) {
    EXPECT_EQ(pairs[static_cast<size_t>(k)].a, k);
    EXPECT_EQ(pairs[static_cast<size_t>(k)].b, k);
    EXPECT_LT(pairs[static_cast<size_t>(k)].chi2, 11.34);
  }
}

TEST(PlaneAssociatorTest, RefusesWhatTheCovarianceCannotExplain) {
  const FacesWorld w;
  const PlaneAssociator associator{PlaneAssociationOptions{}};
  // B's origin 0.25 m off along x and y (a shift every face sees), but a graph that claims 2 cm.
  const Eigen::Isometry3d b_estimate = YawedPose(4.25, 1.25, 0.6);
  EXPECT_TRUE(associator
                  .Associate(w.Seen(w.a), PlacedWithSigma(w.a, 0.01, 0.001), w.Seen(w.b),
                             PlacedWithSigma(b_estimate, 0.02, 0.002))
                  .empty());
}

TEST(PlaneAssociatorTest, LeavesParallelNeighboursOutWhenTheEstimateCannotTellThem) {
  // Two panels 0.4 m apart, one behind the other; B's origin is known to 0.5 m only.
  const Eigen::Isometry3d a = YawedPose(0, 0, 0), b = YawedPose(2, 0, 0);
  const Eigen::Vector3d n(-1, 0, 0);
  const std::vector<SubmapPlane> pa = {testing::FaceSeenFrom(a, n, Eigen::Vector3d(6, 0, 1)),
                                       testing::FaceSeenFrom(a, n, Eigen::Vector3d(6.4, 0, 1))};
  const std::vector<SubmapPlane> pb = {testing::FaceSeenFrom(b, n, Eigen::Vector3d(6, 0, 1)),
                                       testing::FaceSeenFrom(b, n, Eigen::Vector3d(6.4, 0, 1))};
  const PlaneAssociator associator{PlaneAssociationOptions{}};
  EXPECT_TRUE(
      associator.Associate(pa, PlacedWithSigma(a, 0.01, 0.001), pb, PlacedWithSigma(b, 0.5, 0.01)).empty());
  // Known to 3 cm, each finds its own.
  const auto pairs =
      associator.Associate(pa, PlacedWithSigma(a, 0.01, 0.001), pb, PlacedWithSigma(b, 0.03, 0.001));
  ASSERT_EQ(pairs.size(), 2u);
  EXPECT_EQ(pairs[0].b, 0);
  EXPECT_EQ(pairs[1].b, 1);
}

TEST(PlaneAssociatorTest, RefusesFacesSeenFromOppositeSidesOrFarApart) {
  const Eigen::Isometry3d a = YawedPose(0, 0, 0), b = YawedPose(10, 0, 0);
  const SubmapPlane front = testing::FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 0, 1));
  const SubmapPlane back = testing::FaceSeenFrom(b, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(5, 0, 1));
  const PlaneAssociator associator{PlaneAssociationOptions{}};
  EXPECT_LT(
      associator.Distance(front, PlacedWithSigma(a, 0.01, 0.001), back, PlacedWithSigma(b, 0.01, 0.001)),
      0.0);
  // The same wall plane, but the faces 20 m apart along it.
  const SubmapPlane near = testing::FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 0, 1));
  const SubmapPlane far = testing::FaceSeenFrom(b, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 20, 1));
  EXPECT_LT(associator.Distance(near, PlacedWithSigma(a, 0.01, 0.001), far, PlacedWithSigma(b, 0.01, 0.001)),
            0.0);
}

TEST(PlaneAssociatorTest, DistanceFollowsTheStatedCovariance) {
  // An offset error of k sigma (everything else exact) gives a distance of k^2.
  const Eigen::Isometry3d a = YawedPose(0, 0, 0);
  PlaneAssociationOptions o;
  o.min_normal_sigma = o.min_offset_sigma = 0.0;
  const PlaneAssociator associator(o);
  const SubmapPlane pa = testing::FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 0, 1),
                                               Eigen::Vector2d(1.5, 1.5), 0.01);
  const SubmapPlane pb = testing::FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5.03, 0, 1),
                                               Eigen::Vector2d(1.5, 1.5), 0.01);
  // Both planes 0.01 m, origins 0 (constant): sigma of the difference sqrt(2) cm; 3 cm apart.
  const double chi2 = associator.Distance(pa, PlacedWithSigma(a, 0.0, 0.0), pb, PlacedWithSigma(a, 0.0, 0.0));
  EXPECT_NEAR(chi2, 9.0 / 2.0, 1e-3);
}

}  // namespace
}  // namespace cairn
