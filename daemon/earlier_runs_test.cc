#include "daemon/earlier_runs.h"

#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>

#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

void Touch(const fs::path& p, const std::string& text = "x") {
  fs::create_directories(p.parent_path());
  std::ofstream(p) << text;
}

std::string Read(const fs::path& p) {
  std::ifstream in(p);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

TEST(EarlierRunsTest, AMissingOrEmptyFolderHasNothingToKeep) {
  const testing::ScopedTempDir temp("earlier_runs_empty");
  const std::string dir = temp.path();
  auto r = EarlierRuns::Keep(dir + "/not-there", 3, {});
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->moved_entries, 0);
  r = EarlierRuns::Keep(dir, 3, {});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->moved_entries, 0);
  EXPECT_TRUE(r->kept_in.empty());
  EXPECT_FALSE(fs::exists(fs::path(dir) / EarlierRuns::kFolder));
}

// Two restarts: each run's outputs end up whole in their own numbered folder, and what lives
// across runs (the item store, a key file in a folder of the output) stays where it is.
TEST(EarlierRunsTest, EachRestartMovesTheRunBeforeIntoTheNextFolder) {
  const testing::ScopedTempDir temp("earlier_runs_move");
  const fs::path dir = temp.path();
  Touch(dir / "recording-000.mcap", "first");
  Touch(dir / "submaps/rover-000000.submap", "first submap");
  Touch(dir / "exchange/items.log", "store");
  Touch(dir / "keys/rover.key", "key");
  const std::vector<std::string> persistent = {(dir / "exchange").string(), (dir / "keys/rover.key").string()};
  auto r = EarlierRuns::Keep(dir.string(), 5, persistent);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->moved_entries, 2);
  EXPECT_EQ(r->kept_in, (dir / "earlier-runs/1").string());
  EXPECT_EQ(Read(dir / "earlier-runs/1/recording-000.mcap"), "first");
  EXPECT_EQ(Read(dir / "earlier-runs/1/submaps/rover-000000.submap"), "first submap");
  EXPECT_EQ(Read(dir / "exchange/items.log"), "store");
  EXPECT_EQ(Read(dir / "keys/rover.key"), "key");
  EXPECT_FALSE(fs::exists(dir / "recording-000.mcap"));

  Touch(dir / "recording-000.mcap", "second");
  r = EarlierRuns::Keep(dir.string(), 5, persistent);
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->moved_entries, 1);
  EXPECT_EQ(Read(dir / "earlier-runs/2/recording-000.mcap"), "second");
  EXPECT_EQ(Read(dir / "earlier-runs/1/recording-000.mcap"), "first");
}

// Beyond `keep` the oldest folders go, whatever else is in earlier-runs stays; keep 0 keeps none.
TEST(EarlierRunsTest, TheOldestBeyondKeepAreRemoved) {
  const testing::ScopedTempDir temp("earlier_runs_prune");
  const fs::path dir = temp.path();
  Touch(dir / "earlier-runs/notes.txt");
  for (int run = 1; run <= 4; ++run) {
    Touch(dir / "summary.json", std::to_string(run));
    auto r = EarlierRuns::Keep(dir.string(), 2, {});
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->removed_runs, run > 2 ? 1 : 0) << run;
  }
  EXPECT_FALSE(fs::exists(dir / "earlier-runs/1"));
  EXPECT_FALSE(fs::exists(dir / "earlier-runs/2"));
  EXPECT_EQ(Read(dir / "earlier-runs/3/summary.json"), "3");
  EXPECT_EQ(Read(dir / "earlier-runs/4/summary.json"), "4");
  EXPECT_TRUE(fs::exists(dir / "earlier-runs/notes.txt"));

  Touch(dir / "summary.json", "5");
  auto r = EarlierRuns::Keep(dir.string(), 0, {});
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->moved_entries, 1);
  EXPECT_EQ(r->removed_runs, 3);
  EXPECT_TRUE(r->kept_in.empty());
  EXPECT_FALSE(fs::exists(dir / "summary.json"));
  EXPECT_FALSE(fs::exists(dir / "earlier-runs/5"));
}

TEST(EarlierRunsTest, AFileInPlaceOfTheFolderIsAnError) {
  const testing::ScopedTempDir temp("earlier_runs_file");
  const fs::path dir = temp.path();
  Touch(dir / "out", "not a folder");
  const auto r = EarlierRuns::Keep((dir / "out").string(), 3, {});
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find((dir / "out").string()), std::string::npos) << r.status().ToString();
}

}  // namespace
}  // namespace cairn
