#include "estimation/graph/g2o_io.h"

#include <cmath>
#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

namespace cairn {
namespace {

constexpr const char* kSe3 =
    "VERTEX_SE3:QUAT 0 0 0 0 0 0 0 1\n"
    "VERTEX_SE3:QUAT 1 1 2 3 0 0 0.70710678 0.70710678\n"
    "EDGE_SE3:QUAT 0 1 1 2 3 0 0 0.70710678 0.70710678 "
    "100 0 0 0 0 0 100 0 0 0 0 100 0 0 0 400 0 0 400 0 400\n";

TEST(G2oIoTest, ReadsSe3AndRoundTrips) {
  PoseGraph g;
  ASSERT_TRUE(ParseG2o(kSe3, "mem", g).ok());
  ASSERT_EQ(g.num_vertices(), 2u);
  ASSERT_EQ(g.edges().size(), 1u);
  const auto& e = g.edges()[0];
  EXPECT_NEAR(e.information(3, 3), 400.0, 0);
  EXPECT_NEAR(e.tau, 100.0, 1e-9);                       // 3 / tr(I/100 * 3)
  EXPECT_NEAR(e.kappa, 3.0 / (2.0 * 3.0 / 400.0), 1e-9);  // SE-Sync's kappa
  EXPECT_NEAR(g.poses()[1].q.angularDistance(Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()))), 0.0, 1e-7);
  EXPECT_NEAR(SeSyncCost(g), 0.0, 1e-10);
  PoseGraph back;
  ASSERT_TRUE(ParseG2o(FormatG2o(g), "mem2", back).ok());
  EXPECT_EQ(back.ids(), g.ids());
  EXPECT_LT((back.edges()[0].information - e.information).norm(), 1e-9);
  EXPECT_LT((back.poses()[1].t - g.poses()[1].t).norm(), 1e-12);
}

TEST(G2oIoTest, LiftsSe2WithSeSyncWeights) {
  PoseGraph g;
  ASSERT_TRUE(ParseG2o("VERTEX_SE2 0 0 0 0\nVERTEX_SE2 1 1 0 0.5\n"
                       "EDGE_SE2 0 1 1 0 0.5 50 0 0 50 0 200\n",
                       "mem", g).ok());
  const auto& e = g.edges()[0];
  EXPECT_TRUE(e.planar);
  EXPECT_NEAR(e.information(5, 5), 200.0, 0);   // theta -> yaw
  EXPECT_NEAR(e.information(0, 0), 50.0, 0);
  EXPECT_GT(e.information(2, 2), 0.0);          // z, roll, pitch held
  EXPECT_NEAR(e.tau, 50.0, 1e-9);
  EXPECT_NEAR(e.kappa, 200.0, 0);
  EXPECT_NEAR(g.poses()[1].R()(1, 0), std::sin(0.5), 1e-12);
  EXPECT_TRUE(g.planar());
  // Written back as SE2.
  EXPECT_NE(FormatG2o(g).find("EDGE_SE2 0 1 1 0 0.5"), std::string::npos);
}

TEST(G2oIoTest, RejectsMalformedLinesWithFileAndLine) {
  struct Case { const char* text; const char* what; };
  const Case cases[] = {
      {"VERTEX_SE2 0 0 0\n", "mem:1:"},
      {"VERTEX_SE2 0 0 0 0\nEDGE_SE2 0 1 1 0 x 1 0 0 1 0 1\n", "mem:2:"},
      {"VERTEX_SE3:QUAT 0 0 0 0 0 0 0 2\n", "not unit"},
      {"\n\nEDGE_SE2 0 1 1 0 0 1 0 0 -1 0 1\n", "mem:3: information"},
      {"VERTEX_SE2 -4 0 0 0\n", "mem:1:"},
      {"VERTEX_SE2 4 0 0 0 7\n", "trailing"},
      {"FOO 1 2\n", "unknown record"},
      {"VERTEX_SE2 1 nan 0 0\n", "mem:1:"},
  };
  for (const auto& c : cases) {
    PoseGraph g;
    const Status s = ParseG2o(c.text, "mem", g);
    ASSERT_FALSE(s.ok()) << c.text;
    EXPECT_NE(s.message().find(c.what), std::string::npos) << s.message();
  }
}

// Some benchmark files carry information that is not positive definite while its translation and
// rotation blocks are: read, flagged and counted (only the SE-Sync objective can use them); blocks
// that are not positive definite themselves are refused at their line.
TEST(G2oIoTest, IndefiniteInformationIsFlaggedWithWhereItWasFirstRead) {
  // t_x and r_x coupled by 150 with 100 and 100 on the diagonal: eigenvalues -50 and 250.
  const std::string indefinite =
      "EDGE_SE3:QUAT 1 2 1 0 0 0 0 0 1 100 0 0 150 0 0 100 0 0 0 0 100 0 0 0 100 0 0 100 0 100\n";
  PoseGraph g;
  ASSERT_TRUE(ParseG2o(std::string(kSe3) + indefinite + indefinite, "mem", g).ok());
  ASSERT_EQ(g.edges().size(), 3u);
  EXPECT_TRUE(g.edges()[0].definite);
  EXPECT_FALSE(g.edges()[1].definite);
  EXPECT_EQ(g.indefinite_edges(), 2u);
  EXPECT_EQ(g.first_indefinite(), "mem:4");
  EXPECT_NEAR(g.edges()[1].tau, 100.0, 1e-9);
  EXPECT_NEAR(g.edges()[1].kappa, 50.0, 1e-9);
  // Its statistics take what the SE-Sync objective weighs: diag(tau, 2 kappa).
  EXPECT_NEAR(EffectiveInformation(g.edges()[1]).diagonal().norm(), std::sqrt(6.0) * 100.0, 1e-9);
  PoseGraphEdge projected = g.edges()[1];
  ProjectToPositiveDefinite(projected);
  EXPECT_TRUE(projected.definite);
  EXPECT_EQ(projected.information.llt().info(), Eigen::Success);
  PoseGraph bad;
  const Status s = ParseG2o(
      "\nEDGE_SE3:QUAT 1 2 1 0 0 0 0 0 1 100 0 0 0 0 0 -1 0 0 0 0 100 0 0 0 100 0 0 100 0 100\n", "mem", bad);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("mem:2: information matrix is not positive definite, nor are its"),
            std::string::npos)
      << s.message();
}

TEST(G2oIoTest, ReadsMultiRobotDirectoryOnceEachInterRobotEdge) {
  const char* dir = std::getenv("CAIRN_DATA_DIR");
  const std::string path = std::string(dir ? dir : "") + "/posegraphs/multirobot-argos-clean-2robots";
  if (!std::filesystem::exists(path)) GTEST_SKIP() << "missing " << path;
  auto g = ReadG2o(path);
  ASSERT_TRUE(g.ok()) << g.status().message();
  size_t robots_a = 0, robots_b = 0, inter = 0;
  for (uint64_t id : g->ids()) (RobotOfKey(id) == 'a' ? robots_a : robots_b)++;
  for (const auto& e : g->edges()) inter += RobotOfKey(e.from) != RobotOfKey(e.to);
  EXPECT_EQ(robots_a + robots_b, g->num_vertices());
  EXPECT_GT(robots_a, 0u);
  EXPECT_GT(robots_b, 0u);
  EXPECT_GT(inter, 0u);
  EXPECT_LE(inter, 34u);  // listed in both files, counted once
  EXPECT_FALSE(ReadG2o(path + "/missing.g2o").ok());
  // The spoiled set lists its inter-robot closures in both files, some differing in the last digit.
  const std::string spoiled = std::string(dir ? dir : "") + "/posegraphs/multirobot-argos-spoiled-2robots";
  if (!std::filesystem::exists(spoiled)) GTEST_SKIP() << "missing " << spoiled;
  auto s = ReadG2o(spoiled);
  ASSERT_TRUE(s.ok()) << s.status().message();
  size_t spoiled_inter = 0;
  for (const auto& e : s->edges()) spoiled_inter += RobotOfKey(e.from) != RobotOfKey(e.to);
  EXPECT_EQ(spoiled_inter, 30u);
}

}  // namespace
}  // namespace cairn
