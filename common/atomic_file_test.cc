#include "common/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

TEST(AtomicFileTest, ReplacesContentsWithoutLeavingTemporaries) {
  const testing::ScopedTempDir temp("atomic_file");
  const std::filesystem::path dir = temp.path();
  const std::string path = (dir / "f.json").string();
  ASSERT_TRUE(WriteFileAtomically(path, "old").ok());
  ASSERT_TRUE(WriteFileAtomically(path, "new contents").ok());
  std::stringstream s;
  s << std::ifstream(path).rdbuf();
  EXPECT_EQ(s.str(), "new contents");
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
}

TEST(AtomicFileTest, UnwritableFolderIsAnIoError) {
  const Status s = WriteFileAtomically("/nonexistent-dir/cairn/f.json", "x");
  EXPECT_EQ(s.code(), StatusCode::kIoError);
  EXPECT_NE(s.message().find("/nonexistent-dir/cairn/f.json.tmp"), std::string::npos);
}

}  // namespace
}  // namespace cairn
