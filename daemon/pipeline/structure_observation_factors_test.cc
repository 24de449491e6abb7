#include "daemon/pipeline/structure_observation_factors.h"

#include <set>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(StructureObservationFactorsTest, LandmarkKeysKeepTheRunAndNeverCollide) {
  std::set<uint64_t> keys;
  for (uint32_t run = 0; run < 3; ++run) {
    for (uint64_t local = 0; local < 20; ++local) {
      const uint64_t frame = RunIndex(run, local);
      for (uint32_t i = 0; i < 300; i += 7) {
        EXPECT_TRUE(keys.insert(PlaneLandmarkKey('a', frame, i % 256)).second);
        EXPECT_TRUE(keys.insert(LineLandmarkKey('a', frame, i)).second);
      }
      const uint64_t line = LineLandmarkKey('b', frame, kMaxLineIndex);
      EXPECT_EQ(KindOfKey(line), VariableKind::kLine);
      EXPECT_EQ(RobotOfVariable(line), 'b');
      EXPECT_EQ(RunOfIndex(IndexOfVariable(line)), RunOfIndex(frame));
      EXPECT_EQ(KindOfKey(PlaneLandmarkKey('b', frame, 3)), VariableKind::kPlane);
    }
  }
}

TEST(StructureObservationFactorsTest, APlaneLandmarkStartsOnItsFirstFace) {
  TeamPlaneObservation o;
  o.observer_letter = 'a';
  o.creator_letter = 'b';
  o.frame = 4;
  o.creator_frame = 2;
  o.plane = 7;
  o.normal = Eigen::Vector3d(2.0, 0.0, 0.0);  // not unit: the factor takes its direction
  o.offset = -3.0;                            // the plane x = 3
  o.centroid = Eigen::Vector3d(3.2, 1.0, 0.5);
  const Expected<SlamFactor> f = PlaneObservationFactor(o);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  EXPECT_EQ(f->kind, FactorKind::kPlaneObservation);
  EXPECT_EQ(f->a, VariableKey(VariableKind::kSubmap, 'a', 4));
  EXPECT_EQ(f->b, PlaneLandmarkKey('b', 2, 7));
  EXPECT_NEAR(f->plane.head<3>().norm(), 1.0, 1e-12);
  EXPECT_NEAR(f->z.t.x(), 3.0, 1e-12);  // the centroid moved onto the plane
  EXPECT_NEAR(f->z.t.y(), 1.0, 1e-12);
}

TEST(StructureObservationFactorsTest, ALineLandmarkStartsOnItsFirstEdge) {
  TeamLineObservation o;
  o.observer_letter = 'c';
  o.creator_letter = 'c';
  o.frame = 9;
  o.creator_frame = 9;
  o.line = 1000;
  o.point = Eigen::Vector3d(1.0, 2.0, 3.0);
  o.direction = Eigen::Vector3d(0.0, 0.0, -5.0);
  const Expected<SlamFactor> f = LineObservationFactor(o);
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  EXPECT_EQ(f->kind, FactorKind::kLineObservation);
  EXPECT_NEAR(f->line_direction.norm(), 1.0, 1e-12);
  EXPECT_TRUE(f->z.t.isApprox(o.point));
}

TEST(StructureObservationFactorsTest, UnknownRobotsAndIndicesOutOfRangeAreRefused) {
  TeamPlaneObservation p;
  p.observer_letter = 'a';
  EXPECT_EQ(PlaneObservationFactor(p).status().code(), StatusCode::kInvalidArgument);  // no creator
  p.creator_letter = 'a';
  p.observer_plane = kMaxPlaneIndex + 1;
  EXPECT_EQ(PlaneObservationFactor(p).status().code(), StatusCode::kInvalidArgument);
  p.observer_plane = kMaxPlaneIndex;
  EXPECT_TRUE(PlaneObservationFactor(p).ok());
  TeamLineObservation l;
  l.observer_letter = l.creator_letter = 'a';
  l.line = kMaxLineIndex + 1;
  EXPECT_EQ(LineObservationFactor(l).status().code(), StatusCode::kInvalidArgument);
  l.line = kMaxLineIndex;
  EXPECT_TRUE(LineObservationFactor(l).ok());
  l.observer_letter = 0;
  EXPECT_EQ(LineObservationFactor(l).status().code(), StatusCode::kInvalidArgument);
}

}  // namespace
}  // namespace cairn
