#include "mapping/matching/photometric_agreement.h"

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include <Eigen/Geometry>
#include <gtest/gtest.h>

namespace cairn {
namespace {

// Gently rolling ground, one point per 5 cm cell over 4 x 4 m, with a random albedo pattern of
// 20 cm patches (as the simulated ground's), in A's frame.
struct Ground {
  std::vector<Eigen::Vector3d> points;
  std::vector<float> grey;
};

Ground MakeGround(uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> level(40.0f, 200.0f);
  std::vector<float> patch(20 * 20);
  for (float& p : patch) p = level(rng);
  Ground g;
  for (int i = 0; i < 80; ++i) {
    for (int j = 0; j < 80; ++j) {
      const double x = 0.05 * i + 0.025, y = 0.05 * j + 0.025;
      g.points.emplace_back(x, y, 0.1 * std::sin(x) * std::cos(0.7 * y) + 0.025);
      g.grey.push_back(patch[static_cast<size_t>((i / 4) * 20 + j / 4)]);
    }
  }
  return g;
}

// The same ground seen from B: its points in B's frame, T_a_b the truth.
Ground InFrameB(const Ground& a, const FourDofTransform& T_a_b) {
  Ground b = a;
  const Eigen::Isometry3d T_b_a = T_a_b.ToIsometry().inverse();
  for (Eigen::Vector3d& p : b.points) p = T_b_a * p;
  return b;
}

// An alignment centimetres and degrees off (as the ICP leaves one on smooth ground) moves back to
// the truth, to within the score's resolution (its 5 cm voxels; here every point sits at a voxel's
// centre, so the score is flat within half a voxel); one at the truth stays there.
TEST(PhotometricAgreementTest, RefinementMovesXYAndYawToTheBestAgreement) {
  const Ground a = MakeGround(2);
  const FourDofTransform truth(1.2, -0.4, 0.05, 0.6);
  const Ground b = InFrameB(a, truth);
  const PhotometricAgreement check(a.points, a.grey, 0.05);
  const FourDofTransform off(truth.translation() + Eigen::Vector3d(0.09, -0.07, 0.0), truth.yaw() + 0.035);
  PhotometricScore before = check.Score(b.points, b.grey, off), after;
  const FourDofTransform refined = check.Refine(b.points, b.grey, off, 0.04, 0.01, 200, &after);
  EXPECT_GT(after.ncc, before.ncc + 0.2) << before.ncc;
  EXPECT_LT((refined.translation() - truth.translation()).head<2>().norm(), 0.03);
  EXPECT_DOUBLE_EQ(refined.translation().z(), off.translation().z());
  EXPECT_LT(std::abs(WrapAngle(refined.yaw() - truth.yaw())), 0.0125);

  const FourDofTransform kept = check.Refine(b.points, b.grey, truth, 0.04, 0.01, 200, &after);
  EXPECT_LT((kept.translation() - truth.translation()).norm(), 0.01);
  EXPECT_GT(after.ncc, 0.95);
  // The budget of scores holds: with 7 only one round of 6 neighbours is tried.
  check.Refine(b.points, b.grey, off, 0.04, 0.01, 7, &after);
  EXPECT_GE(after.ncc, before.ncc);
}

// Ground 12 m from B's origin, left 1.7 deg off about the ground itself (as an ICP leaves a
// match: the overlap in place, the turn to chance). About B's origin that is also 0.37 m of
// translation; the search turns B about its centroid, so it needs no long zigzag of x, y and yaw
// steps and converges within the budget the matcher used to give it.
TEST(PhotometricAgreementTest, RefinementFarFromTheOriginTurnsAboutTheGround) {
  Ground a = MakeGround(4);
  for (Eigen::Vector3d& p : a.points) p += Eigen::Vector3d(12.0, 3.0, 0.0);
  const FourDofTransform truth(4.0, -2.0, 0.05, 0.4);
  const Ground b = InFrameB(a, truth);
  const PhotometricAgreement check(a.points, a.grey, 0.05);
  const Eigen::Vector2d centre(14.0, 5.0);  // the ground's middle, in A
  const double turn = 0.03;
  const Eigen::Vector2d t = centre + Eigen::Rotation2Dd(turn) * (truth.translation().head<2>() - centre);
  const FourDofTransform off(Eigen::Vector3d(t.x() + 0.05, t.y() - 0.04, truth.translation().z()),
                             truth.yaw() + turn);
  ASSERT_GT((off.translation() - truth.translation()).head<2>().norm(), 0.35);
  PhotometricScore before = check.Score(b.points, b.grey, off), after;
  const FourDofTransform refined = check.Refine(b.points, b.grey, off, 0.04, 0.01, 80, &after);
  EXPECT_GT(after.ncc, before.ncc + 0.2) << before.ncc;
  // Within the score's resolution (half a voxel) at every point of the ground.
  double worst = 0.0;
  for (const Eigen::Vector3d& p : b.points) {
    worst = std::max(worst, (refined.ToIsometry() * p - truth.ToIsometry() * p).norm());
  }
  EXPECT_LT(worst, 0.03);
}

TEST(PhotometricAgreementTest, GreyLevelsAgreeAtTheTrueAlignmentOnly) {
  const Ground a = MakeGround(1);
  const FourDofTransform truth(1.2, -0.4, 0.05, 0.6);
  const Ground b = InFrameB(a, truth);
  const PhotometricAgreement check(a.points, a.grey, 0.05);

  const PhotometricScore right = check.Score(b.points, b.grey, truth);
  EXPECT_GT(right.pairs, a.points.size() * 9 / 10);
  EXPECT_GT(right.ncc, 0.95);
  // Shifted by two patches, or turned by 20 degrees about a point of the ground: the geometry
  // still lies on the ground, the pattern does not.
  const PhotometricScore shifted = check.Score(b.points, b.grey, truth * FourDofTransform(0.4, 0.0, 0.0, 0.0));
  const PhotometricScore turned = check.Score(b.points, b.grey, FourDofTransform(2.0, 2.0, 0.0, 0.35) *
                                                                    FourDofTransform(-2.0, -2.0, 0.0, 0.0) * truth);
  for (const PhotometricScore& s : {shifted, turned}) {
    EXPECT_GT(s.pairs, 500u);
    EXPECT_LT(std::abs(s.ncc), 0.3) << s.pairs;
  }
}

TEST(PhotometricAgreementTest, AnotherCamerasGainAndOffsetDoNotMatter) {
  const Ground a = MakeGround(2);
  const FourDofTransform truth(-0.3, 0.8, 0.0, -1.1);
  Ground b = InFrameB(a, truth);
  for (float& g : b.grey) g = 0.6f * g + 35.0f;
  const PhotometricScore s = PhotometricAgreement(a.points, a.grey, 0.05).Score(b.points, b.grey, truth);
  EXPECT_GT(s.ncc, 0.95);
  // Inverted grey levels correlate negatively: the check's threshold refuses them.
  for (float& g : b.grey) g = 255.0f - g;
  EXPECT_LT(PhotometricAgreement(a.points, a.grey, 0.05).Score(b.points, b.grey, truth).ncc, -0.95);
}

TEST(PhotometricAgreementTest, NoTextureNoOverlapAndBadPointsGiveNoCorrelation) {
  Ground a = MakeGround(3);
  const FourDofTransform truth(0.5, 0.5, 0.0, 0.2);
  Ground b = InFrameB(a, truth);
  // Uniform grey on one side: nothing to correlate.
  std::vector<float> flat(b.grey.size(), 120.0f);
  PhotometricScore s = PhotometricAgreement(a.points, a.grey, 0.05).Score(b.points, flat, truth);
  EXPECT_GT(s.pairs, 1000u);
  EXPECT_TRUE(std::isnan(s.ncc));
  // Far apart: no pair.
  s = PhotometricAgreement(a.points, a.grey, 0.05).Score(b.points, b.grey, FourDofTransform(50.0, 0.0, 0.0, 0.0));
  EXPECT_EQ(s.pairs, 0u);
  EXPECT_TRUE(std::isnan(s.ncc));
  // Empty clouds, and NaN points or grey levels, are skipped; lengths that differ use the shorter.
  EXPECT_EQ(PhotometricAgreement({}, {}, 0.05).Score(b.points, b.grey, truth).pairs, 0u);
  a.points[0] = Eigen::Vector3d::Constant(std::nan(""));
  b.grey[1] = std::nanf("");
  b.grey.pop_back();
  s = PhotometricAgreement(a.points, a.grey, 0.05).Score(b.points, b.grey, truth);
  EXPECT_GT(s.ncc, 0.95);
  EXPECT_LT(s.pairs, b.points.size() - 1);
}

}  // namespace
}  // namespace cairn
