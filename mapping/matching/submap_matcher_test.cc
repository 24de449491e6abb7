#include "mapping/matching/submap_matcher.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <numbers>
#include <random>
#include <vector>

#include <Eigen/Eigenvalues>
#include <gtest/gtest.h>

#include "common/angles.h"
#include "mapping/matching/submap_feature_extractor.h"
#include "mapping/submap_codec.h"
#include "mapping/testing/rock_field_scene.h"

namespace cairn {
namespace {

struct Truth {
  FourDofTransform T_a_b;
};

Truth TruthOf(const testing::ScenePair& pair) {
  const Eigen::Isometry3d T_a_b = pair.T_world_a.inverse() * pair.T_world_b;
  return {FourDofTransform::FromIsometry(T_a_b, 1e-9).value()};
}

double YawError(const FourDofTransform& x, const FourDofTransform& y) { return std::abs(WrapAngle(x.yaw() - y.yaw())); }

void Print(const char* what, const SubmapMatchResult& r) {
  std::printf(
      "[ match   ] %s: %s (%s); %zu correspondences, %zu clusters, %zu hypotheses, %zu gated, %zu on a line; "
      "%.1f ms (correspondences %.1f, hough %.1f, ransac %.1f, icp %.1f)\n",
      what, std::string(MatchStatusName(r.status)).c_str(), r.reason.c_str(), r.correspondences, r.clusters,
      r.hypotheses, r.gated_out, r.spread_rejected, r.times.total_ms, r.times.correspondences_ms,
      r.times.hough_ms, r.times.ransac_ms, r.times.icp_ms);
}

class SubmapMatcherTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    pair_ = new testing::ScenePair(testing::OverlappingSubmaps(7));
    const SubmapFeatureExtractor extractor;
    features_a_ = new SubmapFeatures(extractor.Extract(*pair_->a));
    features_b_ = new SubmapFeatures(extractor.Extract(*pair_->b));
  }
  static void TearDownTestSuite() {
    delete pair_;
    delete features_a_;
    delete features_b_;
  }
  static testing::ScenePair* pair_;
  static SubmapFeatures* features_a_;
  static SubmapFeatures* features_b_;
};
testing::ScenePair* SubmapMatcherTest::pair_ = nullptr;
SubmapFeatures* SubmapMatcherTest::features_a_ = nullptr;
SubmapFeatures* SubmapMatcherTest::features_b_ = nullptr;

TEST_F(SubmapMatcherTest, FeaturesOfASuitableSubmap) {
  const SubmapFeatures& f = *features_a_;
  EXPECT_TRUE(f.suitable()) << f.suitability.message;
  EXPECT_GT(f.described.size(), 50u);
  EXPECT_EQ(f.cloud.size(), pair_->a->points().size());
  EXPECT_FALSE(f.obstacle_box_xy.isEmpty());
  std::printf("[ match   ] features: %zu keypoints described; keypoints %.1f ms, descriptors %.1f ms\n",
              f.described.size(), f.keypoint_ms, f.descriptor_ms);
}

TEST_F(SubmapMatcherTest, RecoversTheTrueTransformWithoutAGuess) {
  const SubmapMatchResult r = SubmapMatcher().Match(*features_a_, *features_b_);
  Print("no guess", r);
  ASSERT_TRUE(r.matched()) << r.reason;
  const FourDofTransform truth = TruthOf(*pair_).T_a_b;
  EXPECT_LT((r.T_a_b.translation() - truth.translation()).norm(), 0.05);
  EXPECT_LT(YawError(r.T_a_b, truth), 0.5 * kDegree);
  // The ground's grey levels agree where the match puts it.
  EXPECT_GT(r.photometric.ncc, 0.9);
  EXPECT_GT(r.photometric.pairs, 1000u);
  // The covariance is a covariance: symmetric, positive definite.
  EXPECT_TRUE(r.covariance.isApprox(r.covariance.transpose()));
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(r.covariance).eigenvalues().minCoeff(), 0.0);
}

// The variant without gravity finds the same match, with no tilt; it refuses to pair features of
// the two variants.
TEST_F(SubmapMatcherTest, SixDofVariantRecoversTheTrueTransform) {
  const SubmapFeatureExtractor extractor({}, ShotFrame::kFull);
  const SubmapFeatures a = extractor.Extract(*pair_->a), b = extractor.Extract(*pair_->b);
  const SubmapMatchResult r = SubmapMatcher().Match(a, b);
  Print("6-DoF", r);
  ASSERT_TRUE(r.matched()) << r.reason;
  EXPECT_EQ(r.dof, 6);
  const FourDofTransform truth = TruthOf(*pair_).T_a_b;
  EXPECT_LT((r.T_a_b.translation() - truth.translation()).norm(), 0.05);
  EXPECT_LT(YawError(r.T_a_b, truth), 0.5 * kDegree);
  EXPECT_LT(r.tilt, 0.5 * kDegree);
  EXPECT_LT((r.T_a_b_full.translation() - r.T_a_b.translation()).norm(), 1e-12);
  EXPECT_GT(Eigen::SelfAdjointEigenSolver<Eigen::Matrix4d>(r.covariance).eigenvalues().minCoeff(), 0.0);

  const SubmapMatchResult mixed = SubmapMatcher().Match(a, *features_b_);
  EXPECT_EQ(mixed.status, MatchStatus::kNoMatch);
  EXPECT_NE(mixed.reason.find("different variants"), std::string::npos) << mixed.reason;
}

TEST_F(SubmapMatcherTest, MatchesTheOtherWayRoundToTheInverse) {
  const SubmapMatchResult ab = SubmapMatcher().Match(*features_a_, *features_b_);
  const SubmapMatchResult ba = SubmapMatcher().Match(*features_b_, *features_a_);
  ASSERT_TRUE(ab.matched() && ba.matched()) << ab.reason << " / " << ba.reason;
  const FourDofTransform loop = ab.T_a_b * ba.T_a_b;
  EXPECT_LT(loop.translation().norm(), 0.05);
  EXPECT_LT(std::abs(loop.yaw()), 0.5 * kDegree);
}

TEST_F(SubmapMatcherTest, AGoodRelativeEstimateKeepsTheMatch) {
  RelativePoseEstimate prior;
  const FourDofTransform truth = TruthOf(*pair_).T_a_b;
  prior.T_a_b = FourDofTransform(truth.translation() + Eigen::Vector3d(0.3, -0.2, 0.05), truth.yaw() + 0.05);
  prior.covariance = Eigen::Vector4d(0.25, 0.25, 0.04, 0.01).asDiagonal();
  const SubmapMatchResult r = SubmapMatcher().Match(*features_a_, *features_b_, prior);
  Print("good guess", r);
  ASSERT_TRUE(r.matched()) << r.reason;
  EXPECT_LT((r.T_a_b.translation() - truth.translation()).norm(), 0.05);
}

// Descriptors that yield no hypothesis (here no cluster can reach the consensus asked for) leave
// the pair unmatched without the grey-level search; with it (the default), the ground's pattern seen from
// above still finds the match, and the search's candidates meet the same gate.
TEST_F(SubmapMatcherTest, TheGreyLevelSearchFindsWhatTheDescriptorsMiss) {
  const SubmapFeatures& b = *features_b_;
  SubmapMatcherOptions options;
  options.ransac.min_inliers = 1'000'000;
  options.grey_search.enabled = false;
  const SubmapMatchResult without = SubmapMatcher(options).Match(*features_a_, b);
  EXPECT_EQ(without.status, MatchStatus::kNoMatch) << without.reason;
  EXPECT_EQ(without.searched, 0u);

  options.grey_search.enabled = true;
  options.grey_search.min_match_ncc = 0.9;  // this scene's true alignment correlates 0.944
  const SubmapMatchResult r = SubmapMatcher(options).Match(*features_a_, b);
  Print("grey-level search", r);
  ASSERT_TRUE(r.matched()) << r.reason;
  EXPECT_GT(r.searched, 0u);
  EXPECT_NE(r.reason.find("grey-level search"), std::string::npos) << r.reason;
  const FourDofTransform truth = TruthOf(*pair_).T_a_b;
  EXPECT_LT((r.T_a_b.translation() - truth.translation()).norm(), 0.05);
  EXPECT_LT(YawError(r.T_a_b, truth), 0.5 * kDegree);

  RelativePoseEstimate wrong;
  wrong.T_a_b = FourDofTransform(truth.translation() + Eigen::Vector3d(1.5, 0.0, 0.0), truth.yaw());
  wrong.covariance = Eigen::Vector4d(0.04, 0.04, 0.01, 0.01).asDiagonal();
  const SubmapMatchResult gated = SubmapMatcher(options).Match(*features_a_, b, wrong);
  EXPECT_EQ(gated.status, MatchStatus::kNoMatch);
  EXPECT_NE(gated.reason.find("searched candidate x off the relative estimate"), std::string::npos)
      << gated.reason;
}

TEST_F(SubmapMatcherTest, AConfidentWrongEstimateGatesTheMatchOut) {
  RelativePoseEstimate prior;
  const FourDofTransform truth = TruthOf(*pair_).T_a_b;
  prior.T_a_b = FourDofTransform(truth.translation() + Eigen::Vector3d(1.5, 0.0, 0.0), truth.yaw());
  prior.covariance = Eigen::Vector4d(0.04, 0.04, 0.01, 0.01).asDiagonal();
  const SubmapMatchResult r = SubmapMatcher().Match(*features_a_, *features_b_, prior);
  Print("wrong guess", r);
  EXPECT_EQ(r.status, MatchStatus::kNoMatch);
  EXPECT_GT(r.gated_out, 0u);
  EXPECT_NE(r.reason.find("x off the relative estimate"), std::string::npos) << r.reason;
  if (r.gated_out > 1) {
    EXPECT_NE(r.reason.find(std::to_string(r.gated_out) + " hypotheses outside the gate"), std::string::npos)
        << r.reason;
  }
}

// Geometry that fits but a ground pattern that does not (here B's grey levels scrambled, as if
// another place of the same shape) is refused, before and after the ICP; with both photometric
// checks off the geometry alone matches.
TEST_F(SubmapMatcherTest, GreyLevelsThatDisagreeRefuseTheMatch) {
  SubmapFeatures scrambled = *features_b_;
  std::mt19937 rng(5);
  std::shuffle(scrambled.cloud_grey.begin(), scrambled.cloud_grey.end(), rng);
  SubmapMatchResult r = SubmapMatcher().Match(*features_a_, scrambled);
  Print("scrambled grey", r);
  EXPECT_EQ(r.status, MatchStatus::kNoMatch);
  EXPECT_GT(r.photometric_rejected, 0u);
  EXPECT_NE(r.reason.find("grey levels correlate"), std::string::npos) << r.reason;

  SubmapMatcherOptions after_icp_only;
  after_icp_only.min_hypothesis_ncc = -1.0;
  r = SubmapMatcher(after_icp_only).Match(*features_a_, scrambled);
  EXPECT_EQ(r.status, MatchStatus::kNoMatch);
  EXPECT_NE(r.reason.find("refinements whose grey levels disagree"), std::string::npos) << r.reason;
  EXPECT_LT(std::abs(r.photometric.ncc), 0.3);

  SubmapMatcherOptions off = after_icp_only;
  off.min_match_ncc = -1.0;
  r = SubmapMatcher(off).Match(*features_a_, scrambled);
  ASSERT_TRUE(r.matched()) << r.reason;
  EXPECT_LT((r.T_a_b.translation() - TruthOf(*pair_).T_a_b.translation()).norm(), 0.05);

}

TEST_F(SubmapMatcherTest, GateNamesTheAxisThatIsOff) {
  RelativePoseEstimate prior;
  prior.covariance = Eigen::Vector4d(0.01, 0.01, 0.01, 0.0001).asDiagonal();
  const SubmapMatcher matcher;
  std::string why;
  EXPECT_TRUE(matcher.WithinGate(FourDofTransform(0.15, -0.15, 0.1, 0.015), prior, &why));
  EXPECT_FALSE(matcher.WithinGate(FourDofTransform(0.0, 0.0, 0.0, 0.03), prior, &why));
  EXPECT_NE(why.find("yaw"), std::string::npos) << why;
  // A yaw across +-pi is a small difference.
  prior.T_a_b = FourDofTransform(0.0, 0.0, 0.0, std::numbers::pi - 0.005);
  EXPECT_TRUE(matcher.WithinGate(FourDofTransform(0.0, 0.0, 0.0, -std::numbers::pi + 0.005), prior, &why));
  // Floors: a prior known to a millimetre still accepts the matcher's own error.
  prior.T_a_b = FourDofTransform();
  prior.covariance = Eigen::Matrix4d::Identity() * 1e-8;
  EXPECT_TRUE(matcher.WithinGate(FourDofTransform(0.04, 0.0, 0.0, 0.0), prior, &why));
  prior.covariance(0, 0) = std::numeric_limits<double>::quiet_NaN();
  EXPECT_FALSE(matcher.WithinGate(FourDofTransform(0.5, 0.0, 0.0, 0.0), prior, &why));
}

// What a teammate matches is the submap after the wire format: at the default bits (points within
// resolution / 8, intensity in steps of 4) the matches are as good as on the exact clouds.
TEST(SubmapMatcherSceneTest, SubmapsFromTheWireMatchAsPreciselyAsTheOriginals) {
  const auto wire = [](const Submap& s) {
    auto bytes = SubmapCodec::Encode(s);
    EXPECT_TRUE(bytes.ok());
    auto back = SubmapCodec::Decode(*bytes);
    EXPECT_TRUE(back.ok());
    return *back;
  };
  ASSERT_EQ(SubmapOptions{}.wire_offset_bits, 2);
  const SubmapFeatureExtractor extractor;
  const SubmapMatcher matcher;
  double sum2[2] = {0.0, 0.0};
  const int kPairs = 3;
  for (int seed = 1; seed <= kPairs; ++seed) {
    const testing::ScenePair pair = testing::OverlappingSubmaps(static_cast<unsigned>(seed));
    const Truth truth = TruthOf(pair);
    for (int on_wire = 0; on_wire < 2; ++on_wire) {
      const auto a = on_wire ? wire(*pair.a) : pair.a;
      const auto b = on_wire ? wire(*pair.b) : pair.b;
      const SubmapMatchResult r = matcher.Match(extractor.Extract(*a), extractor.Extract(*b));
      ASSERT_TRUE(r.matched()) << "seed " << seed << (on_wire ? " from the wire" : "") << ": " << r.reason;
      const FourDofTransform e = truth.T_a_b.inverse() * r.T_a_b;
      EXPECT_LT(e.translation().norm(), 0.01) << "seed " << seed;
      // The grey-level refinement after the ICP resolves yaw to about 0.1 deg here (its 5 cm voxels).
      EXPECT_LT(YawError(r.T_a_b, truth.T_a_b), 0.2 * kDegree) << "seed " << seed;
      sum2[on_wire] += e.translation().squaredNorm();
    }
  }
  const double rms_exact = std::sqrt(sum2[0] / kPairs), rms_wire = std::sqrt(sum2[1] / kPairs);
  std::printf("[ match   ] translation RMS over %d pairs: exact %.2f mm, from the wire %.2f mm\n", kPairs,
              1e3 * rms_exact, 1e3 * rms_wire);
  EXPECT_LT(rms_wire, rms_exact + 0.001);
}

TEST(SubmapMatcherSceneTest, SubmapsOfDisjointPartsDoNotMatch) {
  testing::RockFieldOptions o;
  o.seed = 21;
  const std::vector<testing::ScenePoint> scene = testing::RockField(o);
  testing::SceneSubmapOptions sa, sb;
  sa.x_max = -1.0;
  sb.x_min = 1.0;
  sb.seed = 12;
  sa.viewpoints = {{-4.0, -2.0, 1.5}, {-2.0, 2.0, 1.5}};
  sb.viewpoints = {{2.0, -2.0, 1.5}, {4.0, 2.0, 1.5}};
  const auto a = testing::SceneSubmap(scene, testing::YawPose(0.2, {-3.0, 0.0, 0.0}), sa);
  const auto b = testing::SceneSubmap(scene, testing::YawPose(-0.7, {3.0, 0.5, 0.1}), sb);
  const SubmapFeatureExtractor extractor;
  const SubmapFeatures fa = extractor.Extract(*a), fb = extractor.Extract(*b);
  ASSERT_TRUE(fa.suitable() && fb.suitable()) << fa.suitability.message << " / " << fb.suitability.message;
  const SubmapMatchResult r = SubmapMatcher().Match(fa, fb);
  Print("disjoint", r);
  EXPECT_EQ(r.status, MatchStatus::kNoMatch);
}

TEST(SubmapMatcherSceneTest, DifferentWorldsDoNotMatch) {
  const testing::ScenePair x = testing::OverlappingSubmaps(3), y = testing::OverlappingSubmaps(5);
  const SubmapFeatureExtractor extractor;
  const SubmapMatchResult r = SubmapMatcher().Match(extractor.Extract(*x.a), extractor.Extract(*y.b));
  Print("other world", r);
  EXPECT_EQ(r.status, MatchStatus::kNoMatch);
}

TEST(SubmapMatcherSceneTest, EmptyAndTinySubmapsAreUnsuitableWithTheReason) {
  SubmapMetadata metadata;
  const auto empty = std::make_shared<const Submap>(metadata, std::vector<CloudPoint>{},
                                                    MakeOccupancyTree(metadata.options));
  const SubmapFeatureExtractor extractor;
  const SubmapFeatures fe = extractor.Extract(*empty);
  EXPECT_FALSE(fe.suitable());
  EXPECT_EQ(fe.suitability.reason, SuitabilityReason::kTooFewPoints);
  EXPECT_TRUE(fe.cloud.empty());
  EXPECT_TRUE(fe.obstacle_box_xy.isEmpty());
  const SubmapMatchResult r = SubmapMatcher().Match(fe, fe);
  EXPECT_EQ(r.status, MatchStatus::kUnsuitable);
  EXPECT_NE(r.reason.find("submap A: 0 points"), std::string::npos) << r.reason;
}

TEST(SubmapMatcherSceneTest, NonFinitePointsAreSkipped) {
  const testing::ScenePair pair = testing::OverlappingSubmaps(7);
  std::vector<CloudPoint> points = pair.b->points();
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < points.size(); i += 7) points[i].p.x() = (i % 2 == 0) ? nan : inf;
  const size_t broken = (points.size() + 6) / 7;
  const auto b = std::make_shared<const Submap>(pair.b->metadata(), points,
                                                std::make_unique<octomap::OcTree>(pair.b->tree()));
  const SubmapFeatureExtractor extractor;
  const SubmapFeatures fb = extractor.Extract(*b);
  EXPECT_EQ(fb.suitability.non_finite_points, static_cast<int64_t>(broken));
  ASSERT_TRUE(fb.suitable()) << fb.suitability.message;
  EXPECT_EQ(fb.cloud.size(), points.size() - broken);
  for (const Eigen::Vector3d& p : fb.cloud) ASSERT_TRUE(p.allFinite());
}

TEST(SubmapMatcherSceneTest, UnsuitableSubmapsKeepNoCloudUnlessSearchable) {
  // Without an occupancy tree no keypoint has known space around it.
  const testing::ScenePair pair = testing::OverlappingSubmaps(7);
  const auto b = std::make_shared<const Submap>(pair.b->metadata(), pair.b->points(),
                                                MakeOccupancyTree(pair.b->metadata().options));
  const SubmapFeatures kept = SubmapFeatureExtractor().Extract(*b);
  ASSERT_FALSE(kept.suitable());
  EXPECT_TRUE(kept.searchable) << kept.ground_area;
  EXPECT_TRUE(kept.matchable());
  EXPECT_FALSE(kept.cloud.empty());
  EXPECT_EQ(kept.cloud.size(), kept.cloud_grey.size());
  EXPECT_TRUE(kept.described.descriptors.empty());

  SubmapFeatureOptions never;
  never.min_search_area = 0.0;
  const SubmapFeatures fb = SubmapFeatureExtractor(never).Extract(*b);
  ASSERT_FALSE(fb.suitable());
  EXPECT_FALSE(fb.searchable);
  EXPECT_FALSE(fb.matchable());
  EXPECT_TRUE(fb.cloud.empty());
  EXPECT_EQ(fb.cloud.capacity(), 0u);
  EXPECT_FALSE(fb.obstacle_box_xy.isEmpty());  // still pairs by its extent
  // A suitable submap's features hold its cloud and descriptors; this one holds next to nothing.
  const SubmapFeatures fa = SubmapFeatureExtractor().Extract(*pair.a);
  ASSERT_TRUE(fa.suitable()) << fa.suitability.message;
  EXPECT_GE(fa.memory_bytes(), fa.cloud.size() * sizeof(Eigen::Vector3d) + fa.described.descriptors.size() * sizeof(GravityShot));
  EXPECT_LT(fb.memory_bytes(), fa.memory_bytes() / 10);

  // More ground than the search could use is asked for: not kept either.
  SubmapFeatureOptions large;
  large.min_search_area = kept.ground_area + 1.0;
  EXPECT_FALSE(SubmapFeatureExtractor(large).Extract(*b).searchable);
}

// Submaps of textured ground with no obstacles: the descriptors have nothing, the grey levels seen
// from above still place one on the other.
struct GroundPair {
  std::shared_ptr<const Submap> a, b;
  FourDofTransform T_a_b;
};

// A sees world x <= a_x_max, B x >= b_x_min.
GroundPair GroundOnly(unsigned seed, double a_x_max = 2.0, double b_x_min = -2.0, double yaw_b = 1.4) {
  testing::RockFieldOptions o;
  o.rocks = 0;
  o.boxes = 0;
  o.seed = seed;
  const std::vector<testing::ScenePoint> scene = testing::RockField(o);
  testing::SceneSubmapOptions sa, sb;
  sa.x_max = a_x_max;
  sa.seed = seed + 1;
  sb.x_min = b_x_min;
  sb.seed = seed + 2;
  sa.viewpoints = {{-4.0, -2.0, 1.5}, {0.0, 2.0, 1.5}};
  sb.viewpoints = {{0.0, -2.0, 1.5}, {4.0, 2.0, 1.5}};
  const Eigen::Isometry3d T_world_a = testing::YawPose(0.3, {-1.0, 0.5, 0.1});
  const Eigen::Isometry3d T_world_b = testing::YawPose(yaw_b, {1.2, -0.7, 0.3});
  return {testing::SceneSubmap(scene, T_world_a, sa), testing::SceneSubmap(scene, T_world_b, sb),
          FourDofTransform::FromIsometry(T_world_a.inverse() * T_world_b, 1e-9).value()};
}

TEST(SubmapMatcherSceneTest, GroundWithoutObstaclesMatchesByTheGreyLevelSearchAlone) {
  const GroundPair pair = GroundOnly(7);
  const SubmapFeatureExtractor extractor;
  const SubmapFeatures fa = extractor.Extract(*pair.a), fb = extractor.Extract(*pair.b);
  ASSERT_FALSE(fa.suitable());
  EXPECT_EQ(fa.suitability.reason, SuitabilityReason::kTooFewObstaclePoints);
  ASSERT_TRUE(fa.searchable && fb.searchable) << fa.ground_area << " " << fb.ground_area;
  EXPECT_GT(fa.ground_area, 20.0);
  EXPECT_TRUE(fa.obstacle_box_xy.isEmpty());
  EXPECT_FALSE(fa.match_box_xy().isEmpty());

  const SubmapMatchResult r = SubmapMatcher().Match(fa, fb);
  Print("ground only", r);
  ASSERT_TRUE(r.matched()) << r.reason;
  EXPECT_EQ(r.correspondences, 0u);
  EXPECT_GT(r.searched, 0u);
  EXPECT_NE(r.reason.find("grey-level search"), std::string::npos) << r.reason;
  EXPECT_LT((r.T_a_b.translation() - pair.T_a_b.translation()).norm(), 0.05);
  EXPECT_LT(YawError(r.T_a_b, pair.T_a_b), 0.5 * kDegree);

  // The search is the only way: off, the pair is unsuitable, and says why.
  SubmapMatcherOptions off;
  off.grey_search.enabled = false;
  const SubmapMatchResult without = SubmapMatcher(off).Match(fa, fb);
  EXPECT_EQ(without.status, MatchStatus::kUnsuitable);
  EXPECT_NE(without.reason.find("the grey-level search is off"), std::string::npos) << without.reason;

  // Disjoint parts of the ground: nothing.
  const GroundPair apart = GroundOnly(7, -1.0, 1.0);
  const SubmapMatchResult wrong =
      SubmapMatcher().Match(extractor.Extract(*apart.a), extractor.Extract(*apart.b));
  Print("disjoint ground", wrong);
  EXPECT_EQ(wrong.status, MatchStatus::kNoMatch) << wrong.reason;
}

// With a relative estimate the graph knows well, the gate is narrower than the search's steps:
// B's true yaw here lies half a step (1.5 deg) between two yaws of the full search's grid, and
// the peak's cell may be 0.1 m off, where the gate is 0.05 m and 0.01 rad wide. The search then
// steps from the estimate's yaw, the candidate is gated allowing for the steps, and the refined
// match meets the gate itself.
TEST(SubmapMatcherSceneTest, SearchedCandidatesAreGatedAllowingForTheSearchsSteps) {
  const double grid =
      2.0 * std::numbers::pi / std::ceil(2.0 * std::numbers::pi / GreyLevelSearchOptions().yaw_step);
  const GroundPair pair = GroundOnly(
      7, 2.0, -2.0, 0.3 - std::numbers::pi + (std::round((1.1 + std::numbers::pi) / grid) + 0.5) * grid);
  const SubmapFeatureExtractor extractor;
  const SubmapFeatures fa = extractor.Extract(*pair.a), fb = extractor.Extract(*pair.b);
  ASSERT_TRUE(fa.searchable && fb.searchable);
  RelativePoseEstimate prior;
  prior.T_a_b = pair.T_a_b;
  prior.covariance = Eigen::Vector4d(1e-4, 1e-4, 1e-4, 1e-5).asDiagonal();
  const SubmapMatchResult r = SubmapMatcher().Match(fa, fb, prior);
  Print("ground only, gated", r);
  ASSERT_TRUE(r.matched()) << r.reason;
  EXPECT_NE(r.reason.find("grey-level search"), std::string::npos) << r.reason;
  EXPECT_LT((r.T_a_b.translation() - pair.T_a_b.translation()).norm(), 0.05);
  EXPECT_LT(YawError(r.T_a_b, pair.T_a_b), 0.5 * kDegree);
}

}  // namespace
}  // namespace cairn
