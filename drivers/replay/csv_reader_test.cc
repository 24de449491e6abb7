#include "drivers/replay/csv_reader.h"

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

std::string WriteTemp(const testing::ScopedTempDir& dir, const std::string& name, const std::string& text) {
  const std::string path = dir.path() + "/" + name;
  std::ofstream(path, std::ios::binary) << text;
  return path;
}

TEST(CsvReaderTest, SkipsCommentsBlankLinesAndCarriageReturns) {
  const testing::ScopedTempDir temp("csv_ok");
  const std::string p = WriteTemp(temp, "ok.csv", "#t,a\r\n1, 2\r\n\n3,4\n");
  auto rows = CsvReader::ReadAll(p, 2);
  ASSERT_TRUE(rows.ok()) << rows.status().ToString();
  ASSERT_EQ(rows->size(), 2u);
  EXPECT_EQ((*rows)[1].line, 4);
  EXPECT_EQ(*CsvReader::Int(p, (*rows)[0], 1), 2);
}

TEST(CsvReaderTest, TruncatedLastLineNamesFileAndLine) {
  const testing::ScopedTempDir temp("csv_trunc");
  const std::string p = WriteTemp(temp, "trunc.csv", "1,2,3\n4,5");
  auto rows = CsvReader::ReadAll(p, 3);
  ASSERT_FALSE(rows.ok());
  EXPECT_EQ(rows.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(rows.status().message().find(p + ":2"), std::string::npos) << rows.status().message();
  EXPECT_NE(rows.status().message().find("truncated"), std::string::npos);
}

TEST(CsvReaderTest, NonNumericAndNonFiniteFieldsAreErrors) {
  const testing::ScopedTempDir temp("csv_bad");
  const std::string p = WriteTemp(temp, "bad.csv", "12x,1.5\n7,nan\n");
  auto rows = CsvReader::ReadAll(p, 2);
  ASSERT_TRUE(rows.ok());
  EXPECT_FALSE(CsvReader::Int(p, (*rows)[0], 0).ok());
  EXPECT_NE(CsvReader::Int(p, (*rows)[0], 0).status().message().find(p + ":1: column 1"), std::string::npos);
  EXPECT_FALSE(CsvReader::Double(p, (*rows)[1], 1).ok());
  EXPECT_DOUBLE_EQ(*CsvReader::Double(p, (*rows)[0], 1), 1.5);
}

TEST(CsvReaderTest, MissingFileIsNotFound) {
  EXPECT_EQ(CsvReader::ReadAll("/nonexistent/cairn.csv", 2).status().code(), StatusCode::kNotFound);
}

}  // namespace
}  // namespace cairn
