#include "daemon/cairnd_config.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

#include "sim/sim_robot.h"
#include "sim/terrain.h"
#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

// Every configuration the project ships must load without error.
TEST(ShippedConfigsTest, EveryConfigUnderConfigsLoads) {
  int loaded = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::SourceDir() + "/configs")) {
    if (e.path().extension() != ".yaml") continue;
    auto o = LoadCairndOptions(e.path().string(), {});
    EXPECT_TRUE(o.ok()) << e.path() << ": " << o.status().message();
    ++loaded;
  }
  EXPECT_GE(loaded, 3);
}

// The profiles' live cameras are the simulated robots' (a bench that serves the simulator's images
// to the real drivers needs them to agree), in the convention of imu.T_body_imu.
TEST(ShippedConfigsTest, LiveCamerasAreTheSimulatedRobots) {
  sim::WorldOptions world;
  const sim::Terrain terrain = sim::Terrain::Generate(world);
  const sim::SimRobot rover = sim::MakeRover(terrain, "rover", 0, 1, 5.0, 1.0, world.tag_size);
  const sim::SimRobot hexacopter = sim::MakeHexacopter(terrain, "hexacopter", 1, 1, 5.0, 1.0, world.tag_size);
  for (const auto& [file, robot] : {std::pair{"rover.yaml", &rover}, std::pair{"hexacopter.yaml", &hexacopter}}) {
    SCOPED_TRACE(file);
    auto o = LoadCairndOptions(testing::SourceDir() + "/configs/" + file, {});
    ASSERT_TRUE(o.ok()) << o.status().message();
    EXPECT_TRUE(o->cameras.enabled);
    const StereoCalibration c = o->cameras.Calibration();
    EXPECT_DOUBLE_EQ(o->cameras.aravis.frame_rate_hz, robot->camera_rate_hz);
    for (const auto& [mine, theirs] : {std::pair{&c.left, &robot->stereo.left}, std::pair{&c.right, &robot->stereo.right}}) {
      EXPECT_EQ(mine->intrinsics.width, theirs->intrinsics.width);
      EXPECT_EQ(mine->intrinsics.height, theirs->intrinsics.height);
      EXPECT_DOUBLE_EQ(mine->intrinsics.fx, theirs->intrinsics.fx);
      EXPECT_DOUBLE_EQ(mine->intrinsics.cx, theirs->intrinsics.cx);
      EXPECT_DOUBLE_EQ(mine->intrinsics.cy, theirs->intrinsics.cy);
      EXPECT_LT((mine->T_body_cam.translation() - theirs->T_body_cam.translation()).norm(), 1e-9);
      EXPECT_LT(Eigen::AngleAxisd(mine->T_body_cam.linear().transpose() * theirs->T_body_cam.linear()).angle(), 1e-4);
    }
  }
}

// An output folder's config.yaml from an earlier version (here: the rover profile with one key
// removed and one renamed) still loads for scoring, with each difference noted; the daemon's own
// start-up loading stays strict.
TEST(EarlierRunConfigTest, LoadsWithDefaultsAndNotesTheDifferences) {
  std::ifstream in(testing::SourceDir() + "/configs/rover.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string dof = "  dof: 4", ncc = "\n    min_match_ncc:";  // the matcher's own, not a section's
  ASSERT_NE(yaml.find(dof), std::string::npos);
  ASSERT_NE(yaml.find(ncc), std::string::npos);
  yaml.erase(yaml.find(dof), yaml.find('\n', yaml.find(dof)) - yaml.find(dof) + 1);
  yaml.replace(yaml.find(ncc), ncc.size(), "\n    old_match_ncc:");
  const testing::ScopedTempDir temp("earlier_config");
  const std::string path = temp.path() + "/config.yaml";
  std::ofstream(path) << yaml;

  EXPECT_FALSE(LoadCairndOptions(path, {}).ok());
  std::vector<std::string> notes;
  auto o = LoadEarlierRunOptions(path, &notes);
  ASSERT_TRUE(o.ok()) << o.status().message();
  EXPECT_EQ(o->matching.dof, ShotFrame::kGravity);
  EXPECT_DOUBLE_EQ(o->matching.matcher.min_match_ncc, SubmapMatcherOptions{}.min_match_ncc);
  ASSERT_EQ(notes.size(), 3u);
  std::string all;
  for (const std::string& n : notes) all += n + "\n";
  EXPECT_NE(all.find("missing key 'matching.dof'"), std::string::npos) << all;
  EXPECT_NE(all.find("missing key 'matching.matcher.min_match_ncc'"), std::string::npos) << all;
  EXPECT_NE(all.find("unknown key 'matching.matcher.old_match_ncc'"), std::string::npos) << all;
}

}  // namespace
}  // namespace cairn
