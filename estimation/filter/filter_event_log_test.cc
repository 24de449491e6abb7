#include "estimation/filter/filter_event_log.h"

#include <cstdint>
#include <variant>

#include <gtest/gtest.h>

namespace cairn {
namespace {

Timestamp At(int64_t ms) { return Timestamp::FromNanoseconds(ms * 1000000); }

FilterEvent Clone(int64_t ms, CloneId id) {
  FilterEvent e;
  e.time = At(ms);
  e.data = CloneEvent{id};
  return e;
}

CloneId CloneOf(const FilterEvent& e) {
  const auto* c = std::get_if<CloneEvent>(&e.data);
  return c != nullptr ? c->clone : kNoClone;
}

// Inserts in time order, as the filter does: after the events at or before its time.
uint64_t InsertInOrder(FilterEventLog& log, const FilterEvent& e) {
  EXPECT_TRUE(log.MakeRoom());
  const uint64_t pos = log.InsertPosition(e.time);
  log.Insert(pos, e);
  return pos;
}

TEST(FilterEventLogTest, StartsEmpty) {
  const FilterEventLog log(16);
  EXPECT_EQ(log.capacity(), 16u);
  EXPECT_EQ(log.size(), 0u);
  EXPECT_EQ(log.begin_seq(), 0u);
  EXPECT_EQ(log.next_seq(), 0u);
  EXPECT_EQ(log.end_seq(), 0u);
  EXPECT_EQ(log.InsertPosition(At(5)), 0u);
}

TEST(FilterEventLogTest, InsertsInTimeOrder) {
  FilterEventLog log(8);
  EXPECT_EQ(InsertInOrder(log, Clone(30, 1)), 0u);
  EXPECT_EQ(InsertInOrder(log, Clone(10, 2)), 0u);
  EXPECT_EQ(InsertInOrder(log, Clone(20, 3)), 1u);
  // Equal times keep their arrival order.
  EXPECT_EQ(InsertInOrder(log, Clone(20, 4)), 2u);
  EXPECT_EQ(InsertInOrder(log, Clone(40, 5)), 4u);
  ASSERT_EQ(log.end_seq(), 5u);
  const CloneId expected[] = {2, 3, 4, 1, 5};
  for (uint64_t s = 0; s < 5; ++s) {
    EXPECT_EQ(CloneOf(log.at(s)), expected[s]) << s;
    if (s > 0) {
      EXPECT_LE(log.at(s - 1).time, log.at(s).time);
    }
  }
}

TEST(FilterEventLogTest, InsertsBeforePendingButNotBeforeBegin) {
  FilterEventLog log(8);
  InsertInOrder(log, Clone(10, 1));
  InsertInOrder(log, Clone(20, 2));
  log.Advance();
  log.Advance();
  log.DropProcessed();
  // Older than everything kept: it goes at the oldest kept place, never before begin.
  EXPECT_EQ(log.InsertPosition(At(5)), 2u);
  InsertInOrder(log, Clone(40, 3));
  EXPECT_EQ(InsertInOrder(log, Clone(30, 4)), 2u);
  EXPECT_EQ(CloneOf(log.at(2)), 4u);
  EXPECT_EQ(CloneOf(log.at(3)), 3u);
}

TEST(FilterEventLogTest, WrapsAroundTheRing) {
  FilterEventLog log(4);
  CloneId id = 1;
  for (int64_t ms = 0; ms < 40; ms += 10) InsertInOrder(log, Clone(ms, id++));
  // Keep the log full while it moves through the ring several times.
  for (int i = 0; i < 10; ++i) {
    log.Advance();
    InsertInOrder(log, Clone(100 + 10 * i, id++));
    EXPECT_EQ(log.size(), 4u);
  }
  EXPECT_EQ(log.begin_seq(), 10u);
  EXPECT_EQ(log.end_seq(), 14u);
  for (uint64_t s = log.begin_seq(); s < log.end_seq(); ++s) EXPECT_EQ(CloneOf(log.at(s)), s + 1);
  // An insertion at the oldest kept place moves the later events across the wrap point.
  log.Advance();
  InsertInOrder(log, Clone(165, 100));
  EXPECT_EQ(log.begin_seq(), 11u);
  const CloneId expected[] = {100, 12, 13, 14};
  for (uint64_t s = log.begin_seq(); s < log.end_seq(); ++s) {
    EXPECT_EQ(CloneOf(log.at(s)), expected[s - log.begin_seq()]) << s;
  }
}

TEST(FilterEventLogTest, DropsOldestProcessedWhenFull) {
  FilterEventLog log(4);
  for (CloneId id = 1; id <= 4; ++id) InsertInOrder(log, Clone(static_cast<int64_t>(id) * 10, id));
  // Full of pending events: nothing may go.
  EXPECT_FALSE(log.MakeRoom());
  EXPECT_EQ(log.begin_seq(), 0u);
  log.Advance();
  log.Advance();
  EXPECT_TRUE(log.MakeRoom());
  EXPECT_EQ(log.begin_seq(), 1u);
  log.Insert(log.InsertPosition(At(50)), Clone(50, 5));
  EXPECT_TRUE(log.MakeRoom());
  EXPECT_EQ(log.begin_seq(), 2u);
  log.Insert(log.InsertPosition(At(60)), Clone(60, 6));
  // Only pending events are left.
  EXPECT_FALSE(log.MakeRoom());
  EXPECT_EQ(log.begin_seq(), 2u);
  EXPECT_EQ(log.next_seq(), 2u);
  EXPECT_EQ(CloneOf(log.at(log.begin_seq())), 3u);
}

TEST(FilterEventLogTest, RewindsAndDrops) {
  FilterEventLog log(8);
  for (CloneId id = 1; id <= 5; ++id) InsertInOrder(log, Clone(static_cast<int64_t>(id) * 10, id));
  for (int i = 0; i < 4; ++i) log.Advance();
  log.Rewind(2);
  EXPECT_EQ(log.next_seq(), 2u);
  EXPECT_EQ(log.end_seq(), 5u);
  log.DropBefore(1);
  EXPECT_EQ(log.begin_seq(), 1u);
  log.DropBefore(0);  // never moves back
  EXPECT_EQ(log.begin_seq(), 1u);
  log.DropProcessed();
  EXPECT_EQ(log.begin_seq(), 2u);
  EXPECT_EQ(log.size(), 3u);
}

TEST(FilterEventLogTest, KeepsEachKindsFields) {
  FilterEventLog log(8);
  FilterEvent pose;
  pose.time = At(20);
  pose.result = FilterResult::kRejectedGate;
  RelativePoseEvent& rp = pose.data.emplace<RelativePoseEvent>();
  rp.keyframe = 3;
  rp.current = 7;
  rp.t_k_c = Eigen::Vector3d(0.1, -0.2, 0.3);
  rp.q_k_c = Eigen::Quaterniond(Eigen::AngleAxisd(0.4, Eigen::Vector3d(1.0, 2.0, 3.0).normalized()));
  for (int i = 0; i < 6; ++i) {
    for (int j = 0; j < 6; ++j) rp.covariance(i, j) = 0.5 + i + 6 * j;
  }
  FilterEvent wheel;
  wheel.time = At(30);
  wheel.data = WheelEvent{Eigen::Vector2d(1.5, -0.25), Eigen::Matrix2d{{0.04, 0.01}, {0.01, 0.09}}};
  FilterEvent position;
  position.time = At(40);
  position.data = PositionEvent{Eigen::Vector3d(4.0, 5.0, 6.0), Eigen::Matrix3d::Identity() * 0.3};
  FilterEvent release;
  release.time = At(50);
  release.data = ReleaseEvent{9};

  // Inserted out of order, so that each is moved over slots that held another kind.
  InsertInOrder(log, release);
  InsertInOrder(log, position);
  InsertInOrder(log, wheel);
  InsertInOrder(log, pose);
  InsertInOrder(log, Clone(10, 2));
  ASSERT_EQ(log.end_seq(), 5u);

  EXPECT_EQ(CloneOf(log.at(0)), 2u);
  EXPECT_EQ(log.at(0).result, FilterResult::kPending);

  const auto* p = std::get_if<RelativePoseEvent>(&log.at(1).data);
  ASSERT_NE(p, nullptr);
  EXPECT_EQ(log.at(1).time, At(20));
  EXPECT_EQ(log.at(1).result, FilterResult::kRejectedGate);
  EXPECT_EQ(p->keyframe, 3u);
  EXPECT_EQ(p->current, 7u);
  EXPECT_EQ(p->t_k_c, rp.t_k_c);
  EXPECT_EQ(p->q_k_c.coeffs(), rp.q_k_c.coeffs());
  EXPECT_EQ(p->covariance, rp.covariance);

  const auto* w = std::get_if<WheelEvent>(&log.at(2).data);
  ASSERT_NE(w, nullptr);
  EXPECT_EQ(w->v_xy, Eigen::Vector2d(1.5, -0.25));
  EXPECT_EQ(w->covariance, (Eigen::Matrix2d{{0.04, 0.01}, {0.01, 0.09}}));

  const auto* q = std::get_if<PositionEvent>(&log.at(3).data);
  ASSERT_NE(q, nullptr);
  EXPECT_EQ(q->p_frame_imu, Eigen::Vector3d(4.0, 5.0, 6.0));
  EXPECT_EQ(q->covariance, Eigen::Matrix3d::Identity() * 0.3);

  const auto* r = std::get_if<ReleaseEvent>(&log.at(4).data);
  ASSERT_NE(r, nullptr);
  EXPECT_EQ(r->clone, 9u);
  EXPECT_EQ(log.at(4).time, At(50));
}

}  // namespace
}  // namespace cairn
