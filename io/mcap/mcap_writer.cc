#include "io/mcap/mcap_writer.h"

#include <algorithm>
#include <cerrno>
#include <cstring>

#include "io/mcap/mcap_magic.h"

namespace cairn {
namespace {

enum Op : uint8_t {
  kHeader = 0x01, kFooter = 0x02, kSchema = 0x03, kChannel = 0x04, kMessage = 0x05, kChunk = 0x06,
  kMessageIndex = 0x07, kChunkIndex = 0x08, kStatistics = 0x0B, kSummaryOffset = 0x0E, kDataEnd = 0x0F,
};

}  // namespace

McapWriter::~McapWriter() {
  if (file_ != nullptr) (void)Close();
}

Status McapWriter::Append(std::span<const uint8_t> bytes) {
  if (bytes.empty()) return Status::Ok();
  if (std::fwrite(bytes.data(), 1, bytes.size(), file_) != bytes.size()) {
    return IoError(path_ + ": write failed: " + std::strerror(errno));
  }
  if (in_data_section_) data_crc_.Update(bytes);
  offset_ += bytes.size();
  return Status::Ok();
}

Status McapWriter::Open(const std::string& path, const McapWriterOptions& options) {
  if (file_ != nullptr) return FailedPreconditionError(path_ + ": already open");
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) return IoError(path + ": cannot create: " + std::strerror(errno));
  path_ = path;
  options_ = options;
  offset_ = 0;
  chunk_.buffer().reserve(options.chunk_size + options.chunk_size / 8);
  CAIRN_RETURN_IF_ERROR(Append(kMcapMagic));
  ByteWriter w;
  const size_t len = w.BeginRecord(kHeader);
  w.String(options.profile);
  w.String(options.library);
  w.EndRecord(len);
  CAIRN_RETURN_IF_ERROR(Append(w));
  in_data_section_ = true;
  return Status::Ok();
}

void McapWriter::SchemaRecord(ByteWriter& w, const SchemaInfo& s) {
  const size_t len = w.BeginRecord(kSchema);
  w.U16(s.id);
  w.String(s.name);
  w.String(s.encoding);
  w.U32(static_cast<uint32_t>(s.data.size()));
  w.Bytes(s.data);
  w.EndRecord(len);
}

void McapWriter::ChannelRecord(ByteWriter& w, const ChannelInfo& c) {
  const size_t len = w.BeginRecord(kChannel);
  w.U16(c.id);
  w.U16(c.schema_id);
  w.String(c.topic);
  w.String(c.encoding);
  w.StringMap(c.metadata);
  w.EndRecord(len);
}

Expected<uint16_t> McapWriter::AddSchema(const std::string& name, const std::string& encoding,
                                         std::span<const uint8_t> data) {
  if (file_ == nullptr) return FailedPreconditionError("MCAP writer is not open");
  if (schemas_.size() >= 0xFFFE) return OutOfRangeError(path_ + ": too many schemas");
  SchemaInfo s{static_cast<uint16_t>(schemas_.size() + 1), name, encoding,
               std::vector<uint8_t>(data.begin(), data.end())};
  // In the open chunk, so that a reader of any chunk finds the schema before its messages.
  SchemaRecord(chunk_, s);
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

Expected<uint16_t> McapWriter::AddChannel(const std::string& topic, const std::string& message_encoding,
                                          uint16_t schema_id,
                                          const std::map<std::string, std::string>& metadata) {
  if (file_ == nullptr) return FailedPreconditionError("MCAP writer is not open");
  if (schema_id > schemas_.size()) {
    return InvalidArgumentError(path_ + ": channel '" + topic + "' names unknown schema " + std::to_string(schema_id));
  }
  if (channels_.size() >= 0xFFFF) return OutOfRangeError(path_ + ": too many channels");
  ChannelInfo c{static_cast<uint16_t>(channels_.size()), schema_id, topic, message_encoding, metadata};
  ChannelRecord(chunk_, c);
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

Status McapWriter::Write(uint16_t channel_id, uint32_t sequence, uint64_t log_time,
                         uint64_t publish_time, std::span<const uint8_t> data) {
  if (file_ == nullptr) return FailedPreconditionError("MCAP writer is not open");
  if (channel_id >= channels_.size()) {
    return InvalidArgumentError(path_ + ": message on unknown channel " + std::to_string(channel_id));
  }
  chunk_message_index_[channel_id].emplace_back(log_time, chunk_.size());
  const size_t len = chunk_.BeginRecord(kMessage);
  chunk_.U16(channel_id);
  chunk_.U32(sequence);
  chunk_.U64(log_time);
  chunk_.U64(publish_time);
  chunk_.Bytes(data);
  chunk_.EndRecord(len);
  if (!chunk_has_messages_ || log_time < chunk_start_time_) chunk_start_time_ = log_time;
  if (!chunk_has_messages_ || log_time > chunk_end_time_) chunk_end_time_ = log_time;
  if (message_count_ == 0 || log_time < first_time_) first_time_ = log_time;
  if (message_count_ == 0 || log_time > last_time_) last_time_ = log_time;
  chunk_has_messages_ = true;
  ++message_count_;
  ++channel_message_counts_[channel_id];
  if (chunk_.size() >= options_.chunk_size) return FlushChunk();
  return Status::Ok();
}

Status McapWriter::FlushChunk() {
  if (chunk_.size() == 0) return Status::Ok();
  CAIRN_RETURN_IF_ERROR(Compressor::Compress(options_.compression, chunk_.buffer(), &compressed_));
  ChunkIndexInfo index{};
  index.start_time = chunk_has_messages_ ? chunk_start_time_ : 0;
  index.end_time = chunk_has_messages_ ? chunk_end_time_ : 0;
  index.offset = offset_;
  index.compressed_size = compressed_.size();
  index.uncompressed_size = chunk_.size();

  ByteWriter w;
  const size_t len = w.BeginRecord(kChunk);
  w.U64(index.start_time);
  w.U64(index.end_time);
  w.U64(chunk_.size());
  w.U32(Crc32::Of(chunk_.buffer()));
  w.String(Compressor::Name(options_.compression));
  w.U64(compressed_.size());
  // Header fields first, then the payload straight from the compression buffer.
  const uint64_t record_len = w.size() - len - 8 + compressed_.size();
  for (int i = 0; i < 8; ++i) w.buffer()[len + static_cast<size_t>(i)] = static_cast<uint8_t>(record_len >> (8 * i));
  CAIRN_RETURN_IF_ERROR(Append(w));
  CAIRN_RETURN_IF_ERROR(Append(compressed_));
  index.length = offset_ - index.offset;

  ByteWriter mi;
  for (const auto& [channel, entries] : chunk_message_index_) {
    index.message_index_offsets[channel] = offset_ + mi.size();
    const size_t l = mi.BeginRecord(kMessageIndex);
    mi.U16(channel);
    mi.U32(static_cast<uint32_t>(entries.size() * 16));
    for (const auto& [t, off] : entries) {
      mi.U64(t);
      mi.U64(off);
    }
    mi.EndRecord(l);
  }
  index.message_index_length = mi.size();
  CAIRN_RETURN_IF_ERROR(Append(mi));
  if (std::fflush(file_) != 0) return IoError(path_ + ": flush failed: " + std::strerror(errno));
  chunk_indexes_.push_back(std::move(index));
  chunk_.Clear();
  chunk_message_index_.clear();
  chunk_has_messages_ = false;
  return Status::Ok();
}

Status McapWriter::Close() {
  if (file_ == nullptr) return Status::Ok();
  Status status = FlushChunk();
  if (status.ok()) {
    ByteWriter end;
    const size_t len = end.BeginRecord(kDataEnd);
    in_data_section_ = false;
    end.U32(data_crc_.value());
    end.EndRecord(len);
    status = Append(end);
  }
  if (status.ok()) {
    // Summary: groups by opcode, then one Summary Offset per group.
    const uint64_t summary_start = offset_;
    ByteWriter s;
    std::vector<std::tuple<uint8_t, uint64_t, uint64_t>> groups;
    const auto group = [&](uint8_t op, auto&& body) {
      const size_t begin = s.size();
      body();
      if (s.size() > begin) groups.emplace_back(op, summary_start + begin, s.size() - begin);
    };
    group(kSchema, [&] { for (const auto& x : schemas_) SchemaRecord(s, x); });
    group(kChannel, [&] { for (const auto& x : channels_) ChannelRecord(s, x); });
    group(kChunkIndex, [&] {
      for (const auto& c : chunk_indexes_) {
        const size_t l = s.BeginRecord(kChunkIndex);
        s.U64(c.start_time);
        s.U64(c.end_time);
        s.U64(c.offset);
        s.U64(c.length);
        s.U32(static_cast<uint32_t>(c.message_index_offsets.size() * 10));
        for (const auto& [ch, off] : c.message_index_offsets) {
          s.U16(ch);
          s.U64(off);
        }
        s.U64(c.message_index_length);
        s.String(Compressor::Name(options_.compression));
        s.U64(c.compressed_size);
        s.U64(c.uncompressed_size);
        s.EndRecord(l);
      }
    });
    group(kStatistics, [&] {
      const size_t l = s.BeginRecord(kStatistics);
      s.U64(message_count_);
      s.U16(static_cast<uint16_t>(schemas_.size()));
      s.U32(static_cast<uint32_t>(channels_.size()));
      s.U32(0);  // attachments
      s.U32(0);  // metadata
      s.U32(static_cast<uint32_t>(chunk_indexes_.size()));
      s.U64(message_count_ > 0 ? first_time_ : 0);
      s.U64(message_count_ > 0 ? last_time_ : 0);
      s.U32(static_cast<uint32_t>(channel_message_counts_.size() * 10));
      for (const auto& [ch, n] : channel_message_counts_) {
        s.U16(ch);
        s.U64(n);
      }
      s.EndRecord(l);
    });
    const uint64_t summary_offset_start = summary_start + s.size();
    for (const auto& [op, start, length] : groups) {
      const size_t l = s.BeginRecord(kSummaryOffset);
      s.U8(op);
      s.U64(start);
      s.U64(length);
      s.EndRecord(l);
    }
    // Footer; its CRC covers the summary sections and the footer up to the CRC field.
    s.U8(kFooter);
    s.U64(8 + 8 + 4);  // fixed length, known before the CRC is taken
    s.U64(summary_start);
    s.U64(summary_offset_start);
    const uint32_t crc = Crc32::Of(s.buffer());
    s.U32(crc);
    s.Bytes(kMcapMagic);
    status = Append(s);
  }
  if (std::fclose(file_) != 0 && status.ok()) status = IoError(path_ + ": close failed: " + std::strerror(errno));
  file_ = nullptr;
  return status;
}

}  // namespace cairn
