#include "io/compression.h"

#include <lz4frame.h>
#include <zstd.h>

#include <cstring>

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
  out->resize(uncompressed_size);
  switch (c) {
    case Compression::kNone:
      if (in.size() != uncompressed_size) return DataLossError("uncompressed chunk size mismatch");
      std::memcpy(out->data(), in.data(), in.size());
      return Status::Ok();
    case Compression::kZstd: {
      const size_t n = ZSTD_decompress(out->data(), out->size(), in.data(), in.size());
      if (ZSTD_isError(n)) return DataLossError(std::string("zstd: ") + ZSTD_getErrorName(n));
      if (n != uncompressed_size) return DataLossError("zstd chunk decompressed to the wrong size");
      return Status::Ok();
    }
    case Compression::kLz4: {
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
