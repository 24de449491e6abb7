#pragma once
// Compression of MCAP chunk records: zstd frames or LZ4 frames (MCAP's "zstd" and "lz4"), or none.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "hal/status.h"

namespace cairn {

enum class McapCompression { kNone, kZstd, kLz4 };

class ChunkCodec {
 public:
  // The name MCAP stores in chunk records ("", "zstd", "lz4").
  static std::string_view Name(McapCompression c);
  static Expected<McapCompression> FromName(std::string_view name);

  // Replaces `out` with the compressed bytes (kept allocated across calls). `zstd_level` trades
  // speed for size (1: recordings, which must keep up with the sensors).
  static Status Compress(McapCompression c, std::span<const uint8_t> in, std::vector<uint8_t>* out,
                         int zstd_level = 1);
  // Decompresses into exactly `uncompressed_size` bytes or fails.
  static Status Decompress(McapCompression c, std::span<const uint8_t> in,
                           uint64_t uncompressed_size, std::vector<uint8_t>* out);
};

}  // namespace cairn
