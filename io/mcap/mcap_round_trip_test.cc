#include <cstdio>
#include <filesystem>
#include <fstream>
#include <random>

#include <gtest/gtest.h>

#include "io/mcap/mcap_reader.h"
#include "io/mcap/mcap_writer.h"
#include "tests/support/scoped_temp_dir.h"

namespace cairn {
namespace {

namespace fs = std::filesystem;

struct Sent {
  uint16_t channel;
  uint32_t sequence;
  uint64_t time;
  std::vector<uint8_t> data;
};

// Writes messages of mixed sizes (some larger than a chunk) on three channels.
std::vector<Sent> WriteFile(const std::string& path, Compression compression, bool close = true,
                            McapWriter* keep = nullptr) {
  McapWriter local;
  McapWriter& w = keep != nullptr ? *keep : local;
  McapWriterOptions o;
  o.compression = compression;
  o.chunk_size = 4096;
  EXPECT_TRUE(w.Open(path, o).ok());
  const std::string proto = "syntax = \"proto3\";";
  const auto schema = w.AddSchema("cairn.Test", "protobuf",
                                  {reinterpret_cast<const uint8_t*>(proto.data()), proto.size()});
  EXPECT_TRUE(schema.ok());
  std::vector<uint16_t> ch;
  ch.push_back(*w.AddChannel("/imu", "protobuf", *schema, {{"frame", "imu"}}));
  ch.push_back(*w.AddChannel("/stereo/left", "protobuf", *schema));
  ch.push_back(*w.AddChannel("/raw", "x-cairn", 0));
  std::mt19937 rng(3);
  std::vector<Sent> sent;
  for (uint32_t i = 0; i < 600; ++i) {
    const uint16_t c = ch[i % 3];
    const size_t size = i % 97 == 0 ? 10000 : rng() % 200;
    Sent s{c, i, 1000000000ull + i * 5000000ull, std::vector<uint8_t>(size)};
    for (auto& b : s.data) b = static_cast<uint8_t>(rng());
    EXPECT_TRUE(w.Write(s.channel, s.sequence, s.time, s.time + 7, s.data).ok());
    sent.push_back(std::move(s));
  }
  if (close) {
    EXPECT_TRUE(w.Close().ok());
  }
  return sent;
}

class McapRoundTripTest : public ::testing::TestWithParam<Compression> {};

TEST_P(McapRoundTripTest, MessagesSummaryAndIndexesReadBack) {
  const testing::ScopedTempDir temp("mcap");
  const std::string path = temp.path() + "/rt.mcap";
  const auto sent = WriteFile(path, GetParam());
  McapReader reader(path);
  size_t i = 0;
  bool same = true;
  auto scan = reader.Scan([&](const McapChannel& c, const McapMessageView& m) {
    const Sent& s = sent.at(i++);
    same = same && c.id == s.channel && m.sequence == s.sequence && m.log_time == s.time &&
           m.publish_time == s.time + 7 &&
           std::equal(m.data.begin(), m.data.end(), s.data.begin(), s.data.end());
  });
  ASSERT_TRUE(scan.ok()) << scan.status().ToString();
  EXPECT_TRUE(same);
  EXPECT_EQ(i, sent.size());
  EXPECT_TRUE(scan->reached_data_end);
  EXPECT_FALSE(scan->truncated);
  EXPECT_GT(scan->chunks, 10u);
  EXPECT_EQ(reader.channels().at(0).metadata.at("frame"), "imu");

  auto summary = reader.ReadSummary();
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  ASSERT_TRUE(summary->has_statistics);
  EXPECT_EQ(summary->statistics.message_count, 600u);
  EXPECT_EQ(summary->statistics.channel_count, 3u);
  EXPECT_EQ(summary->statistics.schema_count, 1u);
  EXPECT_EQ(summary->statistics.chunk_count, scan->chunks);
  EXPECT_EQ(summary->statistics.channel_message_counts.at(2), 200u);
  EXPECT_EQ(summary->statistics.message_start_time, sent.front().time);
  EXPECT_EQ(summary->statistics.message_end_time, sent.back().time);
  EXPECT_EQ(summary->channels.size(), 3u);
  EXPECT_EQ(summary->schemas.at(1).name, "cairn.Test");
  ASSERT_EQ(summary->chunk_indexes.size(), scan->chunks);
  // Every index points at a chunk record, and every message index offset at a message index.
  std::ifstream in(path, std::ios::binary);
  std::vector<char> bytes((std::istreambuf_iterator<char>(in)), {});
  for (const auto& c : summary->chunk_indexes) {
    ASSERT_LT(c.chunk_start_offset, bytes.size());
    EXPECT_EQ(bytes[c.chunk_start_offset], 0x06);
    EXPECT_EQ(c.compression, std::string(Compressor::Name(GetParam())));
    for (const auto& [channel, off] : c.message_index_offsets) EXPECT_EQ(bytes[off], 0x07) << channel;
    EXPECT_EQ(c.chunk_start_offset + c.chunk_length + c.message_index_length,
              &c == &summary->chunk_indexes.back() ? c.chunk_start_offset + c.chunk_length + c.message_index_length
                                                   : (&c + 1)->chunk_start_offset);
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, McapRoundTripTest,
                         ::testing::Values(Compression::kNone, Compression::kZstd,
                                           Compression::kLz4));

TEST(McapTruncationTest, CutMidChunkReadsEveryWholeChunk) {
  const testing::ScopedTempDir temp("mcap_cut");
  const std::string dir = temp.path();
  const std::string path = dir + "/cut.mcap";
  const auto sent = WriteFile(path, Compression::kZstd);
  McapReader full(path);
  auto summary = full.ReadSummary();
  ASSERT_TRUE(summary.ok());
  // Cut in the middle of the fifth chunk: the first four chunks' messages survive.
  const McapChunkIndex& fifth = summary->chunk_indexes.at(4);
  fs::resize_file(path, fifth.chunk_start_offset + fifth.chunk_length / 2);
  McapReader cut(path);
  uint64_t expected = 0;
  for (const auto& s : sent) expected += s.time <= summary->chunk_indexes[3].message_end_time;
  auto scan = cut.Scan(nullptr);
  ASSERT_TRUE(scan.ok()) << scan.status().ToString();
  EXPECT_TRUE(scan->truncated);
  EXPECT_EQ(scan->chunks, 4u);
  EXPECT_EQ(scan->messages, expected);
  auto no_summary = cut.ReadSummary();
  ASSERT_FALSE(no_summary.ok());
  EXPECT_NE(no_summary.status().message().find("no footer"), std::string::npos);
}

TEST(McapTruncationTest, UnclosedWriterLeavesAReadableFile) {
  const testing::ScopedTempDir temp("mcap_open");
  const std::string path = temp.path() + "/open.mcap";
  McapWriter w;
  WriteFile(path, Compression::kLz4, /*close=*/false, &w);
  // Simulates SIGKILL: the file stays as written so far; only the open chunk is missing.
  McapReader reader(path);
  auto scan = reader.Scan(nullptr);
  ASSERT_TRUE(scan.ok()) << scan.status().ToString();
  EXPECT_TRUE(scan->truncated);
  EXPECT_GT(scan->messages, 500u);
  EXPECT_LT(scan->messages, 600u);
  ASSERT_TRUE(w.Close().ok());
}

TEST(McapCorruptionTest, FlippedByteInAChunkIsACrcError) {
  const testing::ScopedTempDir temp("mcap_bad");
  const std::string path = temp.path() + "/bad.mcap";
  WriteFile(path, Compression::kNone);
  auto summary = McapReader(path).ReadSummary();
  ASSERT_TRUE(summary.ok());
  const uint64_t at = summary->chunk_indexes[2].chunk_start_offset + summary->chunk_indexes[2].chunk_length - 5;
  {
    std::fstream f(path, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(at));
    char c = 0;
    f.get(c);
    f.seekp(static_cast<std::streamoff>(at));
    f.put(static_cast<char>(c ^ 0x5A));
  }
  auto scan = McapReader(path).Scan(nullptr);
  ASSERT_FALSE(scan.ok());
  EXPECT_NE(scan.status().message().find("CRC mismatch"), std::string::npos) << scan.status().message();
  EXPECT_NE(scan.status().message().find(path), std::string::npos);
}

TEST(McapCorruptionTest, NotAnMcapFile) {
  const testing::ScopedTempDir temp("mcap_not");
  const std::string path = temp.path() + "/x.mcap";
  std::ofstream(path) << "hello, this is not MCAP";
  auto scan = McapReader(path).Scan(nullptr);
  ASSERT_FALSE(scan.ok());
  EXPECT_NE(scan.status().message().find("bad magic"), std::string::npos);
}

TEST(McapWriterTest, EmptyFileIsValidAndChannelsNeedKnownSchemas) {
  const testing::ScopedTempDir temp("mcap_empty");
  const std::string path = temp.path() + "/e.mcap";
  McapWriter w;
  ASSERT_TRUE(w.Open(path, {}).ok());
  EXPECT_FALSE(w.AddChannel("/x", "protobuf", 5).ok());
  EXPECT_FALSE(w.Write(0, 0, 0, 0, {}).ok());
  ASSERT_TRUE(w.Close().ok());
  auto summary = McapReader(path).ReadSummary();
  ASSERT_TRUE(summary.ok()) << summary.status().ToString();
  EXPECT_EQ(summary->statistics.message_count, 0u);
  auto scan = McapReader(path).Scan(nullptr);
  ASSERT_TRUE(scan.ok());
  EXPECT_TRUE(scan->reached_data_end);
}

}  // namespace
}  // namespace cairn
