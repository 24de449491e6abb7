#pragma once

#include "common/options_visitor.h"
#include "daemon/telemetry/image_encoding_options.h"
#include "io/compression.h"

namespace cairn {

// Recording of every raw sensor sample the pipeline consumed into MCAP files in the output folder
// (recording-000.mcap, recording-001.mcap, ... rotated by size).
struct RecordingOptions {
  bool enabled = false;
  Compression compression = Compression::kZstd;
  int64_t chunk_size = 4 << 20;
  int64_t rotate_size = int64_t{1} << 30;
  ImageEncodingOptions images;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Choice("compression", compression, {{"none", Compression::kNone},
                                          {"zstd", Compression::kZstd},
                                          {"lz4", Compression::kLz4}});
    v.Integer("chunk_size", chunk_size, 4096, int64_t{1} << 30, "bytes");
    v.Integer("rotate_size", rotate_size, int64_t{1} << 20, int64_t{1} << 40, "bytes");
    v.Section("images", images);
  }
  Status Validate() const {
    return rotate_size > chunk_size ? Status::Ok()
                                    : InvalidArgumentError("rotate_size must exceed chunk_size");
  }
};

}  // namespace cairn
