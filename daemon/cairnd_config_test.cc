#include "daemon/cairnd_config.h"

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>

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

// An output folder's config.yaml from an earlier version (here: the rover profile with one key
// removed and one renamed) still loads for scoring, with each difference noted; the daemon's own
// start-up loading stays strict.
TEST(EarlierRunConfigTest, LoadsWithDefaultsAndNotesTheDifferences) {
  std::ifstream in(testing::SourceDir() + "/configs/rover.yaml");
  std::stringstream text;
  text << in.rdbuf();
  std::string yaml = text.str();
  const std::string dof = "  dof: 4", ncc = "    min_match_ncc:";
  ASSERT_NE(yaml.find(dof), std::string::npos);
  ASSERT_NE(yaml.find(ncc), std::string::npos);
  yaml.erase(yaml.find(dof), yaml.find('\n', yaml.find(dof)) - yaml.find(dof) + 1);
  yaml.replace(yaml.find(ncc), ncc.size(), "    old_match_ncc:");
  const std::string path = testing::FreshTempDir("earlier_config") + "/config.yaml";
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
