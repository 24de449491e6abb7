// Submaps as files and as teammates send them. An input whose first byte is odd is the rest taken
// as the uncompressed payload, wrapped in a valid header (sizes and checksums right), so that the
// mutations reach the payload's parser instead of stopping at the checksums; otherwise the whole
// input is the file.
#include <cstddef>
#include <cstdint>
#include <span>

#include "io/byte_writer.h"
#include "io/crc32.h"
#include "mapping/submap_codec.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  if (size > 0 && (data[0] & 1) != 0) {
    const std::span<const uint8_t> payload(data + 1, size - 1);
    cairn::ByteWriter body;
    body.U8(1);  // one section, stored uncompressed
    body.U32(static_cast<uint32_t>(payload.size()));
    body.U32(static_cast<uint32_t>(payload.size()));
    body.Bytes(payload);
    cairn::ByteWriter file;
    file.Bytes(std::span(reinterpret_cast<const uint8_t*>("CAIRNSUB"), 8));
    file.U16(cairn::SubmapCodec::kVersion);
    file.U8(0);  // Compression::kNone
    file.U8(0);
    file.U64(payload.size());
    file.U64(body.buffer().size());
    file.U32(cairn::Crc32::Of(payload));
    file.U32(cairn::Crc32::Of(body.buffer()));
    file.Bytes(body.buffer());
    (void)cairn::SubmapCodec::Decode(file.buffer());
    return 0;
  }
  (void)cairn::SubmapCodec::Decode({data, size});
  return 0;
}
