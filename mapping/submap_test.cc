#include "mapping/submap.h"

#include <malloc.h>

#include <gtest/gtest.h>

#include "common/heap_bytes.h"
#include "common/sanitizers.h"

namespace cairn {
namespace {

CameraPoints OnePoint(float x) {
  CameraPoints pts;
  pts.time = Timestamp::FromSeconds(static_cast<double>(x));
  pts.p_local = {Eigen::Vector3f(x, 0.05f, 0.05f)};
  pts.p_cam = pts.p_local;
  pts.intensity = {9};
  pts.obstacle = {1};
  return pts;
}

TEST(OpenSubmapTest, RestartBeginsAnEmptySubmapUnderTheNewId) {
  SubmapOptions so;
  OpenSubmap open(so, "rover1", 3);
  OccupancyIntegrator integ(0.1, 8.0);
  open.Integrate(OnePoint(2.05f), &integ);
  open.AddDistance(1.5);
  const auto first = open.Finish();
  open.Restart(4);
  EXPECT_EQ(open.metadata().id, 4u);
  EXPECT_EQ(open.metadata().robot, "rover1");
  EXPECT_EQ(open.metadata().images, 0u);
  EXPECT_EQ(open.metadata().distance, 0.0);
  EXPECT_EQ(open.cloud().size(), 0u);
  EXPECT_EQ(open.tree().size(), 0u);

  open.Integrate(OnePoint(5.05f), &integ);
  const auto second = open.Finish();
  ASSERT_EQ(second->points().size(), 1u);
  EXPECT_NEAR(second->points()[0].p.x(), 5.05f, 0.05f);
  EXPECT_EQ(second->metadata().id, 4u);
  EXPECT_EQ(second->metadata().images, 1u);
  EXPECT_EQ(second->metadata().start, OnePoint(5.05f).time);
  // The finished submap is untouched by what came after.
  ASSERT_EQ(first->points().size(), 1u);
  EXPECT_NEAR(first->points()[0].p.x(), 2.05f, 0.05f);
  EXPECT_EQ(first->metadata().id, 3u);
  EXPECT_EQ(first->metadata().distance, 1.5);
}

TEST(OpenSubmapTest, RestartOfAnUnusedSubmapOnlyRenamesIt) {
  OpenSubmap open(SubmapOptions{}, "rover1", 0);
  open.Restart(9);
  EXPECT_EQ(open.metadata().id, 9u);
  OccupancyIntegrator integ(0.1, 8.0);
  open.Integrate(OnePoint(1.05f), &integ);
  EXPECT_EQ(open.Finish()->metadata().id, 9u);
}

// A finished submap's tree casts no rays: OctoMap's ray buffer goes, and what the submap reports
// holding is what the heap holds for it.
TEST(SubmapTest, FinishedTreeKeepsNoRayBufferAndCountsItsHeapBlocks) {
  if (CAIRN_ADDRESS_SANITIZER || CAIRN_THREAD_SANITIZER) GTEST_SKIP() << "the sanitizer replaces malloc";
  SubmapOptions so;
  OccupancyIntegrator integ(0.1, 8.0);
  std::vector<CloudPoint> points(100);
  const size_t before = mallinfo2().uordblks;
  auto tree = MakeOccupancyTree(so);
  const size_t with_buffer = mallinfo2().uordblks;
  for (int i = 0; i < 200; ++i) {
    tree->updateNode(octomap::point3d(0.1f * static_cast<float>(i % 20), 0.1f * static_cast<float>(i / 20), 0.0f), true);
  }
  const size_t nodes_before = mallinfo2().uordblks;
  const size_t tree_nodes = tree->size();
  const Submap submap(SubmapMetadata{}, points, std::move(tree));
  const size_t after = mallinfo2().uordblks;
  EXPECT_GT(with_buffer - before, size_t{500000});      // the ray buffer of a new tree
  EXPECT_GT(nodes_before - after, size_t{500000});      // gone once the submap is finished
  EXPECT_EQ(submap.tree().size(), tree_nodes);
  // The submap's count against the heap it holds (its tree and points; `points` was copied) and
  // itself (on the stack here, on the heap when shared).
  const double held = static_cast<double>(after - before + sizeof(Submap));
  EXPECT_NEAR(static_cast<double>(submap.memory_bytes()), held, 0.05 * held + 512);
  EXPECT_GT(submap.memory_bytes(), tree_nodes * HeapBlockBytes(sizeof(octomap::OcTreeNode)));
}

}  // namespace
}  // namespace cairn
