#include "common/atomic_file.h"

#include <filesystem>
#include <fstream>
#include <sstream>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(AtomicFileTest, ReplacesContentsWithoutLeavingTemporaries) {
  const auto dir = std::filesystem::temp_directory_path() / "cairn_atomic_test";
  std::filesystem::remove_all(dir);
  std::filesystem::create_directories(dir);
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
