#pragma once

#include "daemon/image_encoding_options.h"
#include "drivers/mcap/chunk_codec.h"
#include "hal/options_visitor.h"

namespace cairn {

// Recording of every raw sensor sample the pipeline consumed into MCAP files in the output folder
// (recording-000.mcap, recording-001.mcap, ... rotated by size).
struct RecordingOptions {
  bool enabled = false;
  McapCompression compression = McapCompression::kZstd;
  int64_t chunk_size = 4 << 20;
  int64_t rotate_size = int64_t{1} << 30;
  ImageEncodingOptions images;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Choice("compression", compression, {{"none", McapCompression::kNone},
                                          {"zstd", McapCompression::kZstd},
                                          {"lz4", McapCompression::kLz4}});
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
