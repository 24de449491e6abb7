#include "estimation/eval/trajectory.h"

#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "estimation/math/so3.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

std::string Temp(const testing::ScopedTempDir& dir, const std::string& name, const std::string& text) {
  const std::string p = dir.path() + "/" + name;
  std::ofstream(p) << text;
  return p;
}

Trajectory Spiral() {
  Trajectory t;
  t.frame = "world";
  for (int i = 0; i < 50; ++i) {
    StampedPose p;
    p.time = Timestamp::FromNanoseconds(1403715273262142976 + int64_t{i} * 50000123);
    p.T_frame_body.linear() = so3::Exp(Eigen::Vector3d(0.01 * i, -0.02 * i, 0.05 * i));
    p.T_frame_body.translation() = Eigen::Vector3d(std::cos(0.1 * i), std::sin(0.1 * i), 0.01 * i);
    t.poses.push_back(p);
  }
  return t;
}

TEST(TrajectoryTest, EveryFormatRoundTrips) {
  const testing::ScopedTempDir temp("trajectory_rt");
  const Trajectory t = Spiral();
  for (auto [format, ext] : {std::pair{TrajectoryFormat::kTum, "tum"}, std::pair{TrajectoryFormat::kEurocCsv, "csv"},
                             std::pair{TrajectoryFormat::kKitti, "kitti"}}) {
    const std::string path = Temp(temp, std::string("rt.") + ext, TrajectoryIo::Format(t, format));
    const std::string times = Temp(temp, "rt.times", TrajectoryIo::KittiTimes(t));
    EXPECT_EQ(*TrajectoryIo::FormatFromPath(path), format);
    auto back = TrajectoryIo::Read(path, format, format == TrajectoryFormat::kKitti ? times : "");
    ASSERT_TRUE(back.ok()) << back.status().ToString();
    ASSERT_EQ(back->poses.size(), t.poses.size());
    for (size_t i = 0; i < t.poses.size(); ++i) {
      const auto& a = t.poses[i];
      const auto& b = back->poses[i];
      // Times travel as integers in every format: nanoseconds survive exactly.
      EXPECT_EQ(a.time, b.time) << ext << " " << i;
      EXPECT_LT((a.T_frame_body.translation() - b.T_frame_body.translation()).norm(), 1e-8);
      EXPECT_LT(so3::Log(a.T_frame_body.linear().transpose() * b.T_frame_body.linear()).norm(), 1e-8);
    }
  }
}

TEST(TrajectoryTest, MalformedLinesNameFileAndLine) {
  const testing::ScopedTempDir temp("trajectory_bad");
  const std::string tum = Temp(temp, "bad.tum", "# header\n1.0 0 0 0 0 0 0 1\n2.0 0 0 0 0 0 1\n");
  auto a = TrajectoryIo::Read(tum, TrajectoryFormat::kTum);
  ASSERT_FALSE(a.ok());
  EXPECT_NE(a.status().message().find(tum + ":3"), std::string::npos) << a.status().message();
  const std::string q = Temp(temp, "badq.tum", "1.0 0 0 0 0 0 0 2\n");
  EXPECT_NE(TrajectoryIo::Read(q, TrajectoryFormat::kTum).status().message().find("norm"), std::string::npos);
  const std::string csv = Temp(temp, "bad.csv", "12x,0,0,0,1,0,0,0\n");
  EXPECT_FALSE(TrajectoryIo::Read(csv, TrajectoryFormat::kEurocCsv).ok());
  const std::string kitti = Temp(temp, "bad.kitti", "2 0 0 0 0 1 0 0 0 0 1 0\n");
  EXPECT_NE(TrajectoryIo::Read(kitti, TrajectoryFormat::kKitti).status().message().find("orthonormal"),
            std::string::npos);
  const std::string ok_kitti = Temp(temp, "ok.kitti", "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 1 0 1 0 0 0 0 1 0\n");
  const std::string short_times = Temp(temp, "short.times", "0.5\n");
  EXPECT_FALSE(TrajectoryIo::Read(ok_kitti, TrajectoryFormat::kKitti, short_times).ok());
  EXPECT_FALSE(TrajectoryIo::FormatFromPath("x.bin").ok());
  EXPECT_FALSE(TrajectoryIo::FormatFromName("bag").ok());
}

TEST(TrajectoryTest, ReadsEurocGroundTruthWithExtraColumns) {
  const char* env = std::getenv("CAIRN_DATA_DIR");
  const std::string path = std::string(env ? env : CAIRN_TEST_DATA_DIR) +
                           "/euroc-v1_01-micro/mav0/state_groundtruth_estimate0/data.csv";
  if (!fs::exists(path)) GTEST_SKIP() << "missing " << path;
  auto t = TrajectoryIo::Read(path, TrajectoryFormat::kEurocCsv);
  ASSERT_TRUE(t.ok()) << t.status().ToString();
  ASSERT_EQ(t->poses.size(), 2895u);
  EXPECT_EQ(t->poses[0].time.nanoseconds(), 1403715273262142976);
  EXPECT_NEAR(t->poses[0].T_frame_body.translation().x(), 0.878895, 1e-12);
  // First row's quaternion (w x y z) = (0.069433, -0.824237, -0.106942, -0.551702).
  const Eigen::Quaterniond q(t->poses[0].T_frame_body.linear());
  EXPECT_NEAR(std::abs(q.w()), 0.069433, 1e-5);
}

}  // namespace
}  // namespace cairn
