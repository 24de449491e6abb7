#pragma once
// Compact wire format of a finished submap (thesis 5.2.1): metadata, the point cloud quantized to
// its voxel grid (sorted voxel indices as varint deltas plus a centroid offset of
// `wire_offset_bits` per axis, i.e. resolution / 2^bits steps), intensity or colour (each channel
// at `wire_intensity_bits`, as the difference to the mean of its causal face neighbours), obstacle
// bits, and the occupancy tree in OctoMap's binary format (maximum-likelihood free/occupied leaves,
// pruned); each stream compressed on its own (zstd or LZ4), all protected by CRC-32s of the
// compressed and the uncompressed bytes. Version 4 adds a last stream: the viewpoints and the
// planar faces (float32, exact); version 5 adds the straight edges (anchored Pluecker lines) to it.
// Versions 5, 4 and 3 (no such stream) decode, and each is encoded on request, for teammates still
// on an older one; version 2 (4 offset bits, 8 intensity bits, one
// compressed block) and version 1 (raw channels) are not read any more.
//
// Lossy by design: points move by at most resolution / 2^(bits+1) per axis, intensity and colour
// by half a step (exact at 8 bits); both bit counts travel in the submap's options, so decoding and
// encoding again changes nothing. The tree keeps only the free/occupied state of each leaf (loaded
// as the clamping bounds, as OctoMap's .bt does). Obstacle flags are exact. Two points may share a
// voxel (a centroid that float rounding put on the boundary of the next voxel); each is kept.

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "common/status.h"
#include "io/compression.h"
#include "mapping/submap.h"

namespace cairn {

class SubmapCodec {
 public:
  static constexpr uint16_t kVersion = 5;
  static constexpr uint16_t kOldestVersion = 3;

  static Expected<std::vector<uint8_t>> Encode(const Submap& submap,
                                               Compression compression = Compression::kZstd,
                                               uint16_t version = kVersion);
  // Validates everything (magic, version, sizes, checksums, every field and the tree structure)
  // and names the first problem.
  static Expected<std::shared_ptr<const Submap>> Decode(std::span<const uint8_t> bytes);

  // Reads and decodes a file; errors name it. (Writers use Encode and their own atomic write.)
  static Expected<std::shared_ptr<const Submap>> ReadFile(const std::string& path);

  // Checks that `data` is one complete OctoMap binary node stream of a tree of depth 16.
  static Status ValidateOctreeBinary(std::span<const uint8_t> data);
};

}  // namespace cairn
