#include "io/compression.h"

#include <cstring>

#include <lz4frame.h>
#include <zstd.h>


namespace cairn {

std::string_view Compressor::Name(Compression c) {
  switch (c) {
    case Compression::kNone: return "";
    case Compression::kZstd: return "zstd";
    case Compression::kLz4: return "lz4";
  }
  return "";
}

Expected<Compression> Compressor::FromName(std::string_view name) {
  if (name.empty()) return Compression::kNone;
  if (name == "zstd") return Compression::kZstd;
  if (name == "lz4") return Compression::kLz4;
  return DataLossError("unsupported chunk compression '" + std::string(name) + "'");
}

Status Compressor::Compress(Compression c, std::span<const uint8_t> in, std::vector<uint8_t>* out,
                            int zstd_level) {
  switch (c) {
    case Compression::kNone:
      out->assign(in.begin(), in.end());
      return Status::Ok();
    case Compression::kZstd: {
      out->resize(ZSTD_compressBound(in.size()));
      const size_t n = ZSTD_compress(out->data(), out->size(), in.data(), in.size(), zstd_level);
      if (ZSTD_isError(n)) return InternalError(std::string("zstd: ") + ZSTD_getErrorName(n));
      out->resize(n);
      return Status::Ok();
    }
    case Compression::kLz4: {
      LZ4F_preferences_t prefs;
      std::memset(&prefs, 0, sizeof(prefs));
      prefs.frameInfo.contentSize = in.size();
      out->resize(LZ4F_compressFrameBound(in.size(), &prefs));
      const size_t n = LZ4F_compressFrame(out->data(), out->size(), in.data(), in.size(), &prefs);
      if (LZ4F_isError(n)) return InternalError(std::string("lz4: ") + LZ4F_getErrorName(n));
      out->resize(n);
      return Status::Ok();
    }
  }
  return InternalError("unknown compression");
}

Status Compressor::Decompress(Compression c, std::span<const uint8_t> in,
                              uint64_t uncompressed_size, std::vector<uint8_t>* out) {
  // The size comes with the block, from a file or a teammate: checked before it is allocated.
  if (uncompressed_size > kMaxUncompressedBytes) {
    return DataLossError("block claims " + std::to_string(uncompressed_size) + " bytes uncompressed, more than 1 GiB");
  }
  switch (c) {
    case Compression::kNone:
      if (in.size() != uncompressed_size) return DataLossError("uncompressed chunk size mismatch");
      out->assign(in.begin(), in.end());
      return Status::Ok();
    case Compression::kZstd: {
      // Our writers (and most others) put the content size in the frame.
      const unsigned long long content = ZSTD_getFrameContentSize(in.data(), in.size());
      if (content == ZSTD_CONTENTSIZE_ERROR) return DataLossError("zstd: not a zstd frame");
      if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != uncompressed_size) {
        return DataLossError("zstd chunk decompresses to " + std::to_string(content) + " bytes, not the " +
                             std::to_string(uncompressed_size) + " it claims");
      }
      out->resize(uncompressed_size);
      const size_t n = ZSTD_decompress(out->data(), out->size(), in.data(), in.size());
      if (ZSTD_isError(n)) return DataLossError(std::string("zstd: ") + ZSTD_getErrorName(n));
      if (n != uncompressed_size) return DataLossError("zstd chunk decompressed to the wrong size");
      return Status::Ok();
    }
    case Compression::kLz4: {
      // LZ4 expands at most about 255 times.
      if (uncompressed_size > 255 * static_cast<uint64_t>(in.size()) + 64) {
        return DataLossError("lz4 chunk of " + std::to_string(in.size()) + " bytes cannot hold the " +
                             std::to_string(uncompressed_size) + " it claims");
      }
      out->resize(uncompressed_size);
      LZ4F_dctx* ctx = nullptr;
      if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) {
        return InternalError("lz4: cannot create a decompression context");
      }
      size_t dst_size = out->size(), src_size = in.size();
      const size_t r = LZ4F_decompress(ctx, out->data(), &dst_size, in.data(), &src_size, nullptr);
      LZ4F_freeDecompressionContext(ctx);
      if (LZ4F_isError(r)) return DataLossError(std::string("lz4: ") + LZ4F_getErrorName(r));
      if (r != 0 || dst_size != uncompressed_size) return DataLossError("lz4 chunk is truncated or has the wrong size");
      return Status::Ok();
    }
  }
  return InternalError("unknown compression");
}

}  // namespace cairn
