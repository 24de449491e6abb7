#include "mapping/matching/plane_associator.h"

#include <gtest/gtest.h>

#include "estimation/math/so3.h"

namespace cairn {
namespace {

Eigen::Isometry3d YawedPose(double x, double y, double yaw) {
  Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
  T.linear() = so3::Exp(Eigen::Vector3d(0.0, 0.0, yaw));
  T.translation() = Eigen::Vector3d(x, y, 0.0);
  return T;
}

// A face of the world (normal, centre, half size) as the submap at T_w_s measures it.
SubmapPlane FaceSeenFrom(const Eigen::Isometry3d& T_w_s, const Eigen::Vector3d& n_w,
                         const Eigen::Vector3d& c_w, double half = 1.5, double sigma = 0.005) {
  SubmapPlane p;
  const Eigen::Vector3d n = T_w_s.linear().transpose() * n_w.normalized();
  const Eigen::Vector3d c = T_w_s.inverse() * c_w;
  p.normal = n.cast<float>();
  p.offset = static_cast<float>(-n.dot(c));
  p.centroid = c.cast<float>();
  p.covariance = Eigen::Matrix3f::Identity() * static_cast<float>(sigma * sigma);
  p.min = Eigen::Vector2f::Constant(static_cast<float>(-half));
  p.max = Eigen::Vector2f::Constant(static_cast<float>(half));
  p.area = static_cast<float>(4 * half * half);
  p.points = 1000;
  return p;
}

SubmapPlacement PlacedWithSigma(const Eigen::Isometry3d& T, double sigma_t, double sigma_r) {
  SubmapPlacement p;
  p.T_world_submap = T;
  Eigen::Matrix<double, 6, 1> d;
  d << sigma_t, sigma_t, sigma_t, sigma_r, sigma_r, sigma_r;
  p.covariance = d.cwiseAbs2().asDiagonal();
  return p;
}

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
    for (const auto& [n, c] : faces) out.push_back(FaceSeenFrom(T, n, c));
    out.push_back(FaceSeenFrom(T, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(1, 3, 0.2), 0.3));
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
  const std::vector<SubmapPlane> pa = {FaceSeenFrom(a, n, Eigen::Vector3d(6, 0, 1)),
                                       FaceSeenFrom(a, n, Eigen::Vector3d(6.4, 0, 1))};
  const std::vector<SubmapPlane> pb = {FaceSeenFrom(b, n, Eigen::Vector3d(6, 0, 1)),
                                       FaceSeenFrom(b, n, Eigen::Vector3d(6.4, 0, 1))};
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
  const SubmapPlane front = FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 0, 1));
  const SubmapPlane back = FaceSeenFrom(b, Eigen::Vector3d(1, 0, 0), Eigen::Vector3d(5, 0, 1));
  const PlaneAssociator associator{PlaneAssociationOptions{}};
  EXPECT_LT(
      associator.Distance(front, PlacedWithSigma(a, 0.01, 0.001), back, PlacedWithSigma(b, 0.01, 0.001)),
      0.0);
  // The same wall plane, but the faces 20 m apart along it.
  const SubmapPlane near = FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 0, 1));
  const SubmapPlane far = FaceSeenFrom(b, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 20, 1));
  EXPECT_LT(associator.Distance(near, PlacedWithSigma(a, 0.01, 0.001), far, PlacedWithSigma(b, 0.01, 0.001)),
            0.0);
}

TEST(PlaneAssociatorTest, DistanceFollowsTheStatedCovariance) {
  // An offset error of k sigma (everything else exact) gives a distance of k^2.
  const Eigen::Isometry3d a = YawedPose(0, 0, 0);
  PlaneAssociationOptions o;
  o.min_normal_sigma = o.min_offset_sigma = 0.0;
  const PlaneAssociator associator(o);
  const SubmapPlane pa = FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5, 0, 1), 1.5, 0.01);
  const SubmapPlane pb = FaceSeenFrom(a, Eigen::Vector3d(-1, 0, 0), Eigen::Vector3d(5.03, 0, 1), 1.5, 0.01);
  // Both planes 0.01 m, origins 0 (constant): sigma of the difference sqrt(2) cm; 3 cm apart.
  const double chi2 = associator.Distance(pa, PlacedWithSigma(a, 0.0, 0.0), pb, PlacedWithSigma(a, 0.0, 0.0));
  EXPECT_NEAR(chi2, 9.0 / 2.0, 1e-3);
}

}  // namespace
}  // namespace cairn
