#pragma once
// Reads MCAP files written by McapWriter or any other conforming writer: a linear scan over the
// data section (decompressing and CRC-checking chunks) for replay, and the indexed summary for a
// quick look at what a file holds. A file cut short by a crash is read up to its last whole record.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"

namespace cairn {

struct McapSchema {
  uint16_t id = 0;
  std::string name, encoding;
  std::vector<uint8_t> data;
};

struct McapChannel {
  uint16_t id = 0;
  uint16_t schema_id = 0;
  std::string topic, message_encoding;
  std::map<std::string, std::string> metadata;
};

struct McapMessageView {
  uint16_t channel_id = 0;
  uint32_t sequence = 0;
  uint64_t log_time = 0;
  uint64_t publish_time = 0;
  std::span<const uint8_t> data;  // valid during the callback only
};

struct McapChunkIndex {
  uint64_t message_start_time = 0, message_end_time = 0, chunk_start_offset = 0, chunk_length = 0;
  std::map<uint16_t, uint64_t> message_index_offsets;
  uint64_t message_index_length = 0;
  std::string compression;
  uint64_t compressed_size = 0, uncompressed_size = 0;
};

struct McapStatistics {
  uint64_t message_count = 0;
  uint16_t schema_count = 0;
  uint32_t channel_count = 0, attachment_count = 0, metadata_count = 0, chunk_count = 0;
  uint64_t message_start_time = 0, message_end_time = 0;
  std::map<uint16_t, uint64_t> channel_message_counts;
};

struct McapSummary {
  std::map<uint16_t, McapSchema> schemas;
  std::map<uint16_t, McapChannel> channels;
  std::vector<McapChunkIndex> chunk_indexes;
  McapStatistics statistics;
  bool has_statistics = false;
};

struct McapScanResult {
  uint64_t messages = 0;
  uint64_t chunks = 0;
  bool truncated = false;     // the file ends inside a record (e.g. after a crash)
  bool reached_data_end = false;
  bool stopped = false;
};

class McapReader {
 public:
  using MessageCallback = std::function<void(const McapChannel&, const McapMessageView&)>;

  explicit McapReader(std::string path) : path_(std::move(path)) {}

  // Reads the data section in file order. Schemas and channels seen so far are available through
  // channels()/schemas() during and after the scan. `stop`, when given, is asked after every
  // message; returning true ends the scan early (result.stopped).
  Expected<McapScanResult> Scan(const MessageCallback& on_message,
                                const std::function<bool()>& stop = {});
  // Reads the summary section through the footer (fails on files without one, e.g. truncated).
  Expected<McapSummary> ReadSummary() const;

  const std::map<uint16_t, McapChannel>& channels() const { return channels_; }
  const std::map<uint16_t, McapSchema>& schemas() const { return schemas_; }

 private:
  Status HandleRecord(uint8_t op, std::span<const uint8_t> body, const MessageCallback& cb,
                      McapScanResult* result, uint64_t at);
  std::function<bool()> stop_;

  std::string path_;
  std::map<uint16_t, McapChannel> channels_;
  std::map<uint16_t, McapSchema> schemas_;
  std::vector<uint8_t> chunk_buffer_;
};

}  // namespace cairn
