#pragma once
// Writes one MCAP file (format version 0): Header, chunked and compressed messages with their
// Message Index records, Data End, and a summary (schemas, channels, chunk indexes, statistics,
// summary offsets) with CRCs. Chunks go to disk as soon as they fill, so a crash loses at most the
// open chunk and leaves a file that linear readers still read up to the last whole chunk.

#include <cstdint>
#include <cstdio>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "io/byte_writer.h"
#include "io/compression.h"
#include "io/crc32.h"

namespace cairn {

struct McapWriterOptions {
  Compression compression = Compression::kZstd;
  size_t chunk_size = 1 << 20;  // uncompressed bytes before a chunk is closed
  std::string profile;          // "" or an "x-..." profile
  std::string library = "cairn";
};

class McapWriter {
 public:
  McapWriter() = default;
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  Status Open(const std::string& path, const McapWriterOptions& options);
  // Returns the schema id (>= 1).
  Expected<uint16_t> AddSchema(const std::string& name, const std::string& encoding,
                               std::span<const uint8_t> data);
  // Returns the channel id. schema_id 0 means "no schema".
  Expected<uint16_t> AddChannel(const std::string& topic, const std::string& message_encoding,
                                uint16_t schema_id,
                                const std::map<std::string, std::string>& metadata = {});
  Status Write(uint16_t channel_id, uint32_t sequence, uint64_t log_time, uint64_t publish_time,
               std::span<const uint8_t> data);
  // Writes the open chunk, the summary and the footer, and closes the file.
  Status Close();

  bool is_open() const { return file_ != nullptr; }
  // Bytes on disk so far (chunks not yet closed are not counted).
  uint64_t bytes_written() const { return offset_; }
  uint64_t message_count() const { return message_count_; }

 private:
  struct SchemaInfo { uint16_t id; std::string name, encoding; std::vector<uint8_t> data; };
  struct ChannelInfo {
    uint16_t id, schema_id;
    std::string topic, encoding;
    std::map<std::string, std::string> metadata;
  };
  struct ChunkIndexInfo {
    uint64_t start_time, end_time, offset, length;
    std::map<uint16_t, uint64_t> message_index_offsets;
    uint64_t message_index_length, compressed_size, uncompressed_size;
  };

  Status FlushChunk();
  Status Append(const ByteWriter& w) { return Append(w.buffer()); }
  Status Append(std::span<const uint8_t> bytes);
  static void SchemaRecord(ByteWriter& w, const SchemaInfo& s);
  static void ChannelRecord(ByteWriter& w, const ChannelInfo& c);

  std::FILE* file_ = nullptr;
  std::string path_;
  McapWriterOptions options_;
  uint64_t offset_ = 0;
  Crc32 data_crc_;          // over the data section (everything after the magic, before Data End)
  bool in_data_section_ = false;

  std::vector<SchemaInfo> schemas_;
  std::vector<ChannelInfo> channels_;
  std::vector<ChunkIndexInfo> chunk_indexes_;
  std::map<uint16_t, uint64_t> channel_message_counts_;
  uint64_t message_count_ = 0;
  uint64_t first_time_ = 0, last_time_ = 0;

  // The open chunk.
  ByteWriter chunk_;
  std::map<uint16_t, std::vector<std::pair<uint64_t, uint64_t>>> chunk_message_index_;
  uint64_t chunk_start_time_ = 0, chunk_end_time_ = 0;
  bool chunk_has_messages_ = false;
  std::vector<uint8_t> compressed_;
};

}  // namespace cairn
