// Files written by McapWriter are read by an MCAP implementation nobody here wrote: Foxglove's
// @mcap/core, both through the index (with the summary CRC checked) and as a stream (with chunk
// CRCs checked).

#include <cstdlib>
#include <filesystem>

#include <gtest/gtest.h>

#include "io/mcap/mcap_writer.h"
#include "tests/support/js_clients.h"
#include "tests/support/json_value.h"
#include "tests/support/process_runner.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

void WriteSample(const std::string& path, Compression c, bool close, McapWriter* w) {
  McapWriterOptions o;
  o.compression = c;
  o.chunk_size = 2048;
  ASSERT_TRUE(w->Open(path, o).ok());
  const std::string schema = "{\"type\":\"object\"}";
  const auto sid = w->AddSchema("cairn.Sample", "jsonschema",
                                {reinterpret_cast<const uint8_t*>(schema.data()), schema.size()});
  ASSERT_TRUE(sid.ok());
  const auto a = w->AddChannel("/a", "json", *sid);
  const auto b = w->AddChannel("/b", "json", *sid);
  for (uint32_t i = 0; i < 300; ++i) {
    const std::string msg = "{\"i\":" + std::to_string(i) + ",\"pad\":\"" + std::string(i % 50, 'x') + "\"}";
    ASSERT_TRUE(w->Write(i % 2 ? *a : *b, i, 1000 + i, 1000 + i,
                         {reinterpret_cast<const uint8_t*>(msg.data()), msg.size()}).ok());
  }
  if (close) {
    ASSERT_TRUE(w->Close().ok());
  }
}

TEST(McapJsReaderTest, FoxgloveReaderReadsEveryCompressionAndACrashedFile) {
  std::string why_not;
  const std::string js = testing::InstallJsClients(&why_not);
  if (js.empty()) GTEST_SKIP() << why_not;
  const testing::ScopedTempDir temp("mcap_js");
  const std::string dir = temp.path();
  std::vector<std::string> files;
  for (auto [name, c] : {std::pair{"none", Compression::kNone}, std::pair{"zstd", Compression::kZstd},
                         std::pair{"lz4", Compression::kLz4}}) {
    McapWriter w;
    files.push_back(dir + "/" + name + ".mcap");
    WriteSample(files.back(), c, true, &w);
  }
  McapWriter crashed;  // never closed: no summary, no footer, the open chunk missing
  WriteSample(dir + "/crashed.mcap", Compression::kZstd, false, &crashed);
  fs::copy_file(dir + "/crashed.mcap", dir + "/crashed-copy.mcap");
  std::vector<std::string> argv = {"/usr/bin/node", js + "/mcap_check.mjs"};
  argv.insert(argv.end(), files.begin(), files.end());
  argv.push_back(dir + "/crashed-copy.mcap");
  const auto r = testing::RunProcess(argv);
  ASSERT_EQ(r.exit_code, 0) << r.output;
  std::vector<testing::JsonValue> results;
  size_t start = 0;
  for (size_t nl; (nl = r.output.find('\n', start)) != std::string::npos; start = nl + 1) {
    results.push_back(testing::JsonValue::Parse(r.output.substr(start, nl - start)));
  }
  ASSERT_EQ(results.size(), 4u) << r.output;
  for (size_t i = 0; i < 3; ++i) {
    const auto& x = results[i];
    ASSERT_TRUE(x.has("indexed")) << r.output;
    EXPECT_EQ(x["indexed"]["messages"].number(), 300);
    EXPECT_EQ(x["indexed"]["statistics_messages"].number(), 300);
    EXPECT_EQ(x["indexed"]["channels"].number(), 2);
    EXPECT_EQ(x["stream"]["messages"].number(), 300);
    EXPECT_TRUE(x["stream"]["done"].boolean());
  }
  // The crashed file cannot be read through an index, but streams up to its last whole chunk.
  const auto& c = results[3];
  EXPECT_TRUE(c.has("indexed_error"));
  EXPECT_GT(c["stream"]["messages"].number(), 200);
  EXPECT_LT(c["stream"]["messages"].number(), 300);
  ASSERT_TRUE(crashed.Close().ok());
}

}  // namespace
}  // namespace cairn
