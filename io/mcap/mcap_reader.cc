#include "io/mcap/mcap_reader.h"

#include <sys/stat.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>

#include "io/byte_reader.h"
#include "io/compression.h"
#include "io/crc32.h"
#include "io/mcap/mcap_magic.h"

namespace cairn {
namespace {

constexpr size_t kFooterRecordSize = 1 + 8 + 8 + 8 + 4;

struct FileCloser {
  void operator()(std::FILE* f) const { std::fclose(f); }
};
using File = std::unique_ptr<std::FILE, FileCloser>;

McapSchema ParseSchema(ByteReader& r) {
  McapSchema s;
  s.id = r.U16();
  s.name = r.String();
  s.encoding = r.String();
  const auto d = r.Take(r.U32());
  s.data.assign(d.begin(), d.end());
  return s;
}

McapChannel ParseChannel(ByteReader& r) {
  McapChannel c;
  c.id = r.U16();
  c.schema_id = r.U16();
  c.topic = r.String();
  c.message_encoding = r.String();
  c.metadata = r.StringMap();
  return c;
}

std::string At(const std::string& path, uint64_t offset) {
  return path + " at byte " + std::to_string(offset);
}

}  // namespace

Status McapReader::HandleRecord(uint8_t op, std::span<const uint8_t> body,
                                const MessageCallback& cb, McapScanResult* result, uint64_t at) {
  ByteReader r(body);
  switch (op) {
    case 0x03: {
      McapSchema s = ParseSchema(r);
      if (r.failed()) return DataLossError(At(path_, at) + ": malformed schema record");
      if (s.id != 0) schemas_[s.id] = std::move(s);
      return Status::Ok();
    }
    case 0x04: {
      McapChannel c = ParseChannel(r);
      if (r.failed()) return DataLossError(At(path_, at) + ": malformed channel record");
      channels_[c.id] = std::move(c);
      return Status::Ok();
    }
    case 0x05: {
      McapMessageView m;
      m.channel_id = r.U16();
      m.sequence = r.U32();
      m.log_time = r.U64();
      m.publish_time = r.U64();
      if (r.failed()) return DataLossError(At(path_, at) + ": malformed message record");
      m.data = r.Take(r.remaining());
      const auto it = channels_.find(m.channel_id);
      if (it == channels_.end()) {
        return DataLossError(At(path_, at) + ": message on channel " + std::to_string(m.channel_id) +
                             " before its channel record");
      }
      ++result->messages;
      if (cb) cb(it->second, m);
      if (stop_ && stop_()) result->stopped = true;
      return Status::Ok();
    }
    case 0x06: {
      r.U64();  // message_start_time
      r.U64();  // message_end_time
      const uint64_t uncompressed_size = r.U64();
      const uint32_t crc = r.U32();
      const std::string compression = r.String();
      const auto payload = r.Take(r.U64());
      if (r.failed()) return DataLossError(At(path_, at) + ": malformed chunk record");
      auto codec = Compressor::FromName(compression);
      if (!codec.ok()) return codec.status().WithContext(At(path_, at));
      std::vector<uint8_t> records;  // a chunk may hold chunks' worth of nested data: own buffer
      records.swap(chunk_buffer_);
      CAIRN_RETURN_IF_ERROR(Compressor::Decompress(*codec, payload, uncompressed_size, &records)
                                .WithContext(At(path_, at)));
      if (crc != 0 && Crc32::Of(records) != crc) {
        return DataLossError(At(path_, at) + ": chunk CRC mismatch");
      }
      ByteReader inner(records);
      while (inner.remaining() > 0) {
        const uint64_t inner_at = inner.position();
        const uint8_t inner_op = inner.U8();
        const auto inner_body = inner.Take(inner.U64());
        if (inner.failed()) return DataLossError(At(path_, at) + ": chunk record at " + std::to_string(inner_at) + " overruns the chunk");
        CAIRN_RETURN_IF_ERROR(HandleRecord(inner_op, inner_body, cb, result, at));
        if (result->stopped) break;
      }
      ++result->chunks;
      chunk_buffer_.swap(records);
      return Status::Ok();
    }
    default:
      return Status::Ok();  // index, attachment, metadata records: not needed for a scan
  }
}

Expected<McapScanResult> McapReader::Scan(const MessageCallback& on_message,
                                          const std::function<bool()>& stop) {
  stop_ = stop;
  File f(std::fopen(path_.c_str(), "rb"));
  if (!f) return NotFoundError(path_ + ": cannot open: " + std::strerror(errno));
  uint8_t magic[8];
  if (std::fread(magic, 1, 8, f.get()) != 8 || std::memcmp(magic, kMcapMagic, 8) != 0) {
    return DataLossError(path_ + ": not an MCAP file (bad magic)");
  }
  // A record longer than the rest of the file is a truncated file, not a size to allocate.
  struct stat st {};
  const uint64_t file_size = fstat(fileno(f.get()), &st) == 0 ? static_cast<uint64_t>(st.st_size) : UINT64_MAX;
  McapScanResult result;
  uint64_t offset = 8;
  std::vector<uint8_t> body;
  bool first = true;
  while (true) {
    uint8_t head[9];
    const size_t n = std::fread(head, 1, 9, f.get());
    if (n == 0) {
      result.truncated = true;  // no footer: the writer never closed the file
      break;
    }
    if (n < 9) {
      result.truncated = true;
      break;
    }
    const uint8_t op = head[0];
    uint64_t len = 0;
    for (int i = 0; i < 8; ++i) len |= static_cast<uint64_t>(head[1 + i]) << (8 * i);
    if (first && op != 0x01) return DataLossError(path_ + ": first record is not a header");
    first = false;
    if (len > (uint64_t{1} << 40)) return DataLossError(At(path_, offset) + ": implausible record length");
    if (len > file_size - std::min(file_size, offset + 9)) {
      result.truncated = true;
      break;
    }
    body.resize(static_cast<size_t>(len));
    if (std::fread(body.data(), 1, body.size(), f.get()) != body.size()) {
      result.truncated = true;
      break;
    }
    if (op == 0x0F) {
      result.reached_data_end = true;
      break;
    }
    CAIRN_RETURN_IF_ERROR(HandleRecord(op, body, on_message, &result, offset));
    if (result.stopped) break;
    offset += 9 + len;
  }
  return result;
}

Expected<McapSummary> McapReader::ReadSummary() const {
  File f(std::fopen(path_.c_str(), "rb"));
  if (!f) return NotFoundError(path_ + ": cannot open: " + std::strerror(errno));
  if (std::fseek(f.get(), 0, SEEK_END) != 0) return IoError(path_ + ": cannot seek");
  const long size = std::ftell(f.get());
  if (size < static_cast<long>(8 + kFooterRecordSize + 8)) return DataLossError(path_ + ": too short for an MCAP footer");
  std::vector<uint8_t> tail(kFooterRecordSize + 8);
  std::fseek(f.get(), size - static_cast<long>(tail.size()), SEEK_SET);
  if (std::fread(tail.data(), 1, tail.size(), f.get()) != tail.size()) return IoError(path_ + ": read failed");
  if (std::memcmp(tail.data() + kFooterRecordSize, kMcapMagic, 8) != 0 || tail[0] != 0x02) {
    return DataLossError(path_ + ": no footer (the file was not closed; scan it instead)");
  }
  ByteReader fr(std::span<const uint8_t>(tail).subspan(9));
  const uint64_t summary_start = fr.U64();
  const uint64_t summary_offset_start = fr.U64();
  const uint32_t summary_crc = fr.U32();
  McapSummary summary;
  if (summary_start == 0) return summary;
  const uint64_t footer_at = static_cast<uint64_t>(size) - tail.size();
  if (summary_start > footer_at) return DataLossError(path_ + ": summary offset beyond the footer");
  std::vector<uint8_t> s(static_cast<size_t>(footer_at - summary_start));
  std::fseek(f.get(), static_cast<long>(summary_start), SEEK_SET);
  if (std::fread(s.data(), 1, s.size(), f.get()) != s.size()) return IoError(path_ + ": read failed");
  if (summary_crc != 0) {
    Crc32 crc;
    crc.Update(s);
    crc.Update(std::span<const uint8_t>(tail).first(9 + 16));
    if (crc.value() != summary_crc) return DataLossError(path_ + ": summary CRC mismatch");
  }
  const uint64_t summary_end = summary_offset_start != 0 ? summary_offset_start - summary_start : s.size();
  ByteReader r(std::span<const uint8_t>(s).first(static_cast<size_t>(summary_end)));
  while (r.remaining() > 0) {
    const uint8_t op = r.U8();
    ByteReader b(r.Take(r.U64()));
    if (r.failed()) return DataLossError(path_ + ": malformed summary section");
    if (op == 0x03) {
      McapSchema x = ParseSchema(b);
      summary.schemas[x.id] = std::move(x);
    } else if (op == 0x04) {
      McapChannel x = ParseChannel(b);
      summary.channels[x.id] = std::move(x);
    } else if (op == 0x08) {
      McapChunkIndex c;
      c.message_start_time = b.U64();
      c.message_end_time = b.U64();
      c.chunk_start_offset = b.U64();
      c.chunk_length = b.U64();
      c.message_index_offsets = b.U16Map(&ByteReader::U64);
      c.message_index_length = b.U64();
      c.compression = b.String();
      c.compressed_size = b.U64();
      c.uncompressed_size = b.U64();
      summary.chunk_indexes.push_back(std::move(c));
    } else if (op == 0x0B) {
      McapStatistics& st = summary.statistics;
      st.message_count = b.U64();
      st.schema_count = b.U16();
      st.channel_count = b.U32();
      st.attachment_count = b.U32();
      st.metadata_count = b.U32();
      st.chunk_count = b.U32();
      st.message_start_time = b.U64();
      st.message_end_time = b.U64();
      st.channel_message_counts = b.U16Map(&ByteReader::U64);
      summary.has_statistics = true;
    }
    if (b.failed()) return DataLossError(path_ + ": malformed summary record (opcode " + std::to_string(op) + ")");
  }
  return summary;
}

}  // namespace cairn
