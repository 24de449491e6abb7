#include "sim/world_file.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/scoped_temp_dir.h"
#include "tests/support/test_data.h"

namespace cairn::sim {
namespace {

std::string Write(const testing::ScopedTempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.path() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(WorldFileTest, WrittenWorldReadsBackIdentically) {
  const testing::ScopedTempDir temp("world");
  WorldOptions w;
  w.seed = 99;
  w.size = 44.0;
  w.lander = {1.0, 2.0};
  auto back = LoadWorldFile(Write(temp, "w.yaml", WorldFileText(w)));
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->seed, 99);
  EXPECT_DOUBLE_EQ(back->size, 44.0);
  EXPECT_EQ(back->lander, w.lander);
}

TEST(WorldFileTest, InvalidWorldsAreRejectedNamingFileLineAndKey) {
  const testing::ScopedTempDir temp("world");
  WorldOptions w;
  std::string text = WorldFileText(w);
  const size_t at = text.find("\nsize: ");
  ASSERT_NE(at, std::string::npos) << text;
  text.replace(at, text.find('\n', at + 1) - at, "\nsize: 5");
  text += "craters: 3\n";
  const std::string path = Write(temp, "bad.yaml", text);
  auto r = LoadWorldFile(path);
  ASSERT_FALSE(r.ok());
  const std::string msg = r.status().message();
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("size"), std::string::npos) << msg;
  EXPECT_NE(msg.find("craters"), std::string::npos) << msg;

  auto missing = LoadWorldFile(Write(temp, "m.yaml", "size: 60\n"));
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("seed"), std::string::npos) << missing.status().message();

  auto not_yaml = LoadWorldFile(Write(temp, "n.yaml", "size: [60\n"));
  EXPECT_FALSE(not_yaml.ok());
  EXPECT_FALSE(LoadWorldFile("/nonexistent/world.yaml").ok());

  std::string lander = WorldFileText(w);
  const size_t l = lander.find("lander: [");
  ASSERT_NE(l, std::string::npos) << lander;
  lander.replace(l, lander.find('\n', l) - l, "lander: [29.5, 0]");
  auto off = LoadWorldFile(Write(temp, "l.yaml", lander));
  ASSERT_FALSE(off.ok());
  EXPECT_NE(off.status().message().find("lander"), std::string::npos) << off.status().message();
}

}  // namespace
}  // namespace cairn::sim

namespace cairn::sim {
namespace {

TEST(WorldFileTest, ShippedDefaultWorldIsTheBuiltInDefault) {
  auto w = LoadWorldFile(testing::SourceDir() + "/configs/worlds/default.yaml");
  ASSERT_TRUE(w.ok()) << w.status().ToString();
  EXPECT_EQ(WorldFileText(*w), WorldFileText(WorldOptions{}));
}

// Every world the project ships must load without error.
TEST(WorldFileTest, EveryShippedWorldLoads) {
  int loaded = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::SourceDir() + "/configs/worlds")) {
    if (e.path().extension() != ".yaml") continue;
    auto w = LoadWorldFile(e.path().string());
    EXPECT_TRUE(w.ok()) << e.path() << ": " << w.status().message();
    ++loaded;
  }
  EXPECT_GE(loaded, 1);
}

}  // namespace
}  // namespace cairn::sim
