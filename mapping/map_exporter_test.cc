#include "mapping/map_exporter.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>
#include <opencv2/imgcodecs.hpp>

#include "mapping/testing/submap_test_util.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

TEST(MapExporterTest, CloudsRoundTripThroughPcdAndPly) {
  const testing::ScopedTempDir temp("map_exporter");
  const std::string dir = temp.path();
  const auto submap = testing::SyntheticSubmap(1, 1);
  for (const char* name : {"/c.pcd", "/c.ply"}) {
    ASSERT_TRUE(MapExporter::WriteCloud(submap->points(), dir + name).ok());
    auto back = MapExporter::ReadCloud(dir + name);
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    ASSERT_EQ(back->size(), submap->points().size());
    for (size_t i = 0; i < back->size(); i += 101) {
      EXPECT_EQ((*back)[i].p, submap->points()[i].p);
      EXPECT_EQ((*back)[i].obstacle, submap->points()[i].obstacle);
      EXPECT_EQ((*back)[i].g, submap->points()[i].g);
    }
  }
  EXPECT_EQ(MapExporter::WriteCloud(submap->points(), dir + "/c.xyz").code(), StatusCode::kInvalidArgument);
  std::ofstream(dir + "/bad.pcd") << "VERSION 0.7\nFIELDS x y z rgb obstacle\nPOINTS 10\nDATA binary\n1234";
  EXPECT_EQ(MapExporter::ReadCloud(dir + "/bad.pcd").status().code(), StatusCode::kDataLoss);
}

TEST(MapExporterTest, OctreesAreReadableByOctomap) {
  const testing::ScopedTempDir temp("map_exporter_tree");
  const std::string dir = temp.path();
  const auto submap = testing::SyntheticSubmap(1, 1);
  ASSERT_TRUE(MapExporter::WriteOctree(submap->tree(), dir + "/m.bt").ok());
  ASSERT_TRUE(MapExporter::WriteOctree(submap->tree(), dir + "/m.ot").ok());
  octomap::OcTree bt(0.1);
  ASSERT_TRUE(bt.readBinary(dir + "/m.bt"));
  std::unique_ptr<octomap::AbstractOcTree> ot(octomap::AbstractOcTree::read(dir + "/m.ot"));
  ASSERT_NE(ot, nullptr);
  auto* full = dynamic_cast<octomap::OcTree*>(ot.get());
  ASSERT_NE(full, nullptr);
  for (auto it = submap->tree().begin_leafs(); it != submap->tree().end_leafs(); ++it) {
    const octomap::OcTreeNode* n = full->search(it.getKey());
    ASSERT_NE(n, nullptr);
    EXPECT_FLOAT_EQ(n->getLogOdds(), it->getLogOdds());
    const octomap::OcTreeNode* m = bt.search(it.getKey());
    ASSERT_NE(m, nullptr);
    EXPECT_EQ(bt.isNodeOccupied(m), submap->tree().isNodeOccupied(*it));
  }
}

TEST(MapExporterTest, GridMapFollowsTheMapServerConvention) {
  const testing::ScopedTempDir temp("map_exporter_grid");
  const std::string dir = temp.path();
  GridMap g;
  g.resolution = 0.05;
  g.origin_x = -1.0;
  g.origin_y = 2.0;
  g.width = 4;
  g.height = 3;
  g.values.assign(12, NAN);
  g.values[0] = 2.0f;   // (0, 0): bottom-left, untraversable
  g.values[11] = 0.5f;  // (3, 2): top-right, traversable
  ASSERT_TRUE(MapExporter::WriteGridMap(g, dir + "/grid.png").ok());
  const cv::Mat img = cv::imread(dir + "/grid.png", cv::IMREAD_UNCHANGED);
  ASSERT_EQ(img.rows, 3);
  ASSERT_EQ(img.cols, 4);
  EXPECT_EQ(img.at<uint8_t>(2, 0), 0);
  EXPECT_EQ(img.at<uint8_t>(0, 3), 254);
  EXPECT_EQ(img.at<uint8_t>(1, 1), 205);
  std::ifstream y(dir + "/grid.yaml");
  std::stringstream ss;
  ss << y.rdbuf();
  EXPECT_NE(ss.str().find("image: grid.png"), std::string::npos);
  EXPECT_NE(ss.str().find("origin: [-1, 2, 0.0]"), std::string::npos) << ss.str();
  EXPECT_NE(ss.str().find("resolution: 0.05"), std::string::npos);
}

}  // namespace
}  // namespace cairn
