#pragma once
// Compression of byte blocks (MCAP chunks, submaps on the wire): zstd frames, LZ4 frames or none.

#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "common/status.h"

namespace cairn {

enum class Compression { kNone, kZstd, kLz4 };

class Compressor {
 public:
  // The block's compression by name ("", "zstd", "lz4"): what MCAP stores in chunk records.
  static std::string_view Name(Compression c);
  static Expected<Compression> FromName(std::string_view name);

  // Replaces `out` with the compressed bytes (kept allocated across calls). `zstd_level` trades
  // speed for size (1: recordings, which must keep up with the sensors).
  static Status Compress(Compression c, std::span<const uint8_t> in, std::vector<uint8_t>* out,
                         int zstd_level = 1);
  static constexpr uint64_t kMaxUncompressedBytes = uint64_t{1} << 30;

  // Decompresses into exactly `uncompressed_size` bytes or fails, without allocating a size the
  // compressed bytes cannot hold (at most kMaxUncompressedBytes).
  static Status Decompress(Compression c, std::span<const uint8_t> in,
                           uint64_t uncompressed_size, std::vector<uint8_t>* out);
};

}  // namespace cairn
