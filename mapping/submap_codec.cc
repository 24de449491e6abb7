#include "mapping/submap_codec.h"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstring>
#include <fstream>
#include <sstream>
#include <string>

#include "io/byte_reader.h"
#include "io/byte_writer.h"
#include "io/crc32.h"

namespace cairn {
namespace {

constexpr char kMagic[8] = {'C', 'A', 'I', 'R', 'N', 'S', 'U', 'B'};
constexpr uint64_t kMaxPayload = uint64_t{1} << 30;
constexpr int kMaxSections = 16;
constexpr int kTreeDepth = 16;
// zstd level of the body: a submap is sent over a poor radio link, but it is encoded on the mapping
// thread, where level 9 took up to 0.4 s for a hexacopter submap for about 2 % less size.
constexpr int kZstdLevel = 3;

void F64(ByteWriter& w, double v) { w.U64(std::bit_cast<uint64_t>(v)); }
double F64(ByteReader& r) { return std::bit_cast<double>(r.U64()); }
void F32(ByteWriter& w, float v) { w.U32(std::bit_cast<uint32_t>(v)); }
float F32(ByteReader& r) { return std::bit_cast<float>(r.U32()); }

// Caps of the structure stream, far above what a submap holds, against counts that lie.
constexpr uint32_t kMaxViewpoints = 1u << 20;
constexpr uint32_t kMaxPlanes = 1u << 16;
constexpr uint32_t kMaxLines = 1u << 16;
constexpr uint64_t kPlaneBytes = 19 * 4;  // 18 floats and the point count
constexpr uint64_t kLineBytes = 33 * 4;   // 32 floats and the sighting count

void WriteLines(const std::vector<SubmapLine>& lines, ByteWriter& w) {
  w.U32(static_cast<uint32_t>(lines.size()));
  for (const SubmapLine& l : lines) {
    for (int a = 0; a < 3; ++a) F32(w, l.anchor[a]);
    for (int a = 0; a < 3; ++a) F32(w, l.moment[a]);
    for (int a = 0; a < 3; ++a) F32(w, l.direction[a]);
    F32(w, l.t_min);
    F32(w, l.t_max);
    for (int i = 0; i < 6; ++i) {
      for (int j = i; j < 6; ++j) F32(w, l.covariance(i, j));
    }
    w.U32(l.sightings);
  }
}

Status ReadLines(ByteReader& r, std::vector<SubmapLine>* lines) {
  const uint32_t count = r.U32();
  if (r.failed() || count > kMaxLines || uint64_t{count} * kLineBytes != r.remaining())
    return DataLossError("submap line count " + std::to_string(count) + " does not match the data");
  lines->resize(count);
  for (uint32_t k = 0; k < count; ++k) {
    SubmapLine& l = (*lines)[k];
    for (int a = 0; a < 3; ++a) l.anchor[a] = F32(r);
    for (int a = 0; a < 3; ++a) l.moment[a] = F32(r);
    for (int a = 0; a < 3; ++a) l.direction[a] = F32(r);
    l.t_min = F32(r);
    l.t_max = F32(r);
    for (int i = 0; i < 6; ++i) {
      for (int j = i; j < 6; ++j) l.covariance(i, j) = l.covariance(j, i) = F32(r);
    }
    l.sightings = r.U32();
    const std::string at = "submap line " + std::to_string(k) + ": ";
    if (!l.anchor.allFinite() || !l.moment.allFinite() || !l.direction.allFinite())
      return DataLossError(at + "anchor, moment or direction is not finite");
    if (std::abs(l.direction.norm() - 1.0f) > 1e-3f)
      return DataLossError(at + "direction is not a unit vector");
    // The moment is perpendicular to the direction (the Pluecker constraint), to float precision.
    if (std::abs(l.moment.dot(l.direction)) > 1e-3f * std::max(1.0f, l.moment.norm()))
      return DataLossError(at + "moment is not perpendicular to the direction");
    if (!(l.t_min <= l.t_max) || !std::isfinite(l.t_min) || !std::isfinite(l.t_max))
      return DataLossError(at + "ends are invalid");
    if (!l.covariance.allFinite() || (l.covariance.diagonal().array() < 0.0f).any())
      return DataLossError(at + "covariance is not finite or has a negative variance");
  }
  return Status::Ok();
}

void WriteStructure(const SubmapStructure& s, uint16_t version, ByteWriter& w) {
  w.U32(static_cast<uint32_t>(s.viewpoints.size()));
  for (const Eigen::Vector3f& v : s.viewpoints) {
    for (int a = 0; a < 3; ++a) F32(w, v[a]);
  }
  w.U32(static_cast<uint32_t>(s.planes.size()));
  for (const SubmapPlane& p : s.planes) {
    for (int a = 0; a < 3; ++a) F32(w, p.normal[a]);
    F32(w, p.offset);
    for (int a = 0; a < 3; ++a) F32(w, p.centroid[a]);
    for (int i = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j) F32(w, p.covariance(i, j));
    }
    for (int a = 0; a < 2; ++a) F32(w, p.min[a]);
    for (int a = 0; a < 2; ++a) F32(w, p.max[a]);
    F32(w, p.area);
    w.U32(p.points);
  }
  if (version >= 5) WriteLines(s.lines, w);
}

Status ReadStructure(ByteReader& r, uint16_t version, SubmapStructure* s) {
  const uint32_t views = r.U32();
  if (r.failed() || views > kMaxViewpoints || uint64_t{views} * 12 > r.remaining())
    return DataLossError("submap viewpoint count " + std::to_string(views) + " exceeds the data");
  s->viewpoints.resize(views);
  for (uint32_t i = 0; i < views; ++i) {
    for (int a = 0; a < 3; ++a) s->viewpoints[i][a] = F32(r);
    if (!s->viewpoints[i].allFinite())
      return DataLossError("submap viewpoint " + std::to_string(i) + " is not finite");
  }
  const uint32_t planes = r.U32();
  // Version 5 has the lines (at least their count) after the planes.
  const uint64_t plane_bytes = uint64_t{planes} * kPlaneBytes;
  if (r.failed() || planes > kMaxPlanes ||
      (version >= 5 ? plane_bytes + 4 > r.remaining() : plane_bytes != r.remaining()))
    return DataLossError("submap plane count " + std::to_string(planes) + " does not match the data");
  s->planes.resize(planes);
  for (uint32_t k = 0; k < planes; ++k) {
    SubmapPlane& p = s->planes[k];
    for (int a = 0; a < 3; ++a) p.normal[a] = F32(r);
    p.offset = F32(r);
    for (int a = 0; a < 3; ++a) p.centroid[a] = F32(r);
    for (int i = 0; i < 3; ++i) {
      for (int j = i; j < 3; ++j) p.covariance(i, j) = p.covariance(j, i) = F32(r);
    }
    for (int a = 0; a < 2; ++a) p.min[a] = F32(r);
    for (int a = 0; a < 2; ++a) p.max[a] = F32(r);
    p.area = F32(r);
    p.points = r.U32();
    const std::string at = "submap plane " + std::to_string(k) + ": ";
    if (!p.normal.allFinite() || std::abs(p.normal.norm() - 1.0f) > 1e-3f)
      return DataLossError(at + "normal is not a unit vector");
    if (!std::isfinite(p.offset) || !p.centroid.allFinite())
      return DataLossError(at + "offset or centroid is not finite");
    if (!p.covariance.allFinite() || (p.covariance.diagonal().array() < 0.0f).any())
      return DataLossError(at + "covariance is not finite or has a negative variance");
    if (!(p.min.array() <= p.max.array()).all() || !(p.area >= 0.0f && std::isfinite(p.area)))
      return DataLossError(at + "extent or area is invalid");
  }
  if (version >= 5) return ReadLines(r, &s->lines);
  return Status::Ok();
}

void Varint(std::vector<uint8_t>& out, uint64_t v) {
  while (v >= 0x80) {
    out.push_back(static_cast<uint8_t>(v | 0x80));
    v >>= 7;
  }
  out.push_back(static_cast<uint8_t>(v));
}
bool Varint(ByteReader& r, uint64_t* v) {
  *v = 0;
  for (int shift = 0; shift < 64; shift += 7) {
    const uint8_t b = r.U8();
    if (r.failed()) return false;
    *v |= static_cast<uint64_t>(b & 0x7F) << shift;
    if (!(b & 0x80)) return true;
  }
  return false;
}

// Binary occupancy data of a maximum-likelihood, pruned copy (the submap itself stays untouched).
std::string TreeBinary(const octomap::OcTree& tree) {
  octomap::OcTree copy(tree);
  copy.toMaxLikelihood();
  copy.prune();
  std::ostringstream s;
  copy.writeBinaryData(s);
  return s.str();
}

// Intensity/colour prediction (version 2): the rounded mean of the channel at the point's causal
// face neighbours (the cells at x-1, y-1, z-1, which come earlier in index order). Neighbouring
// voxels see similar texture, so the residuals compress about a quarter better than raw values.
class ChannelPredictor {
 public:
  explicit ChannelPredictor(const Eigen::Vector3i& extent)
      : steps_{1, static_cast<uint64_t>(extent.x()),
               static_cast<uint64_t>(extent.x()) * static_cast<uint64_t>(extent.y())} {}

  // The first points of the neighbour cells of point i (cell `d` in the extent), -1 when none;
  // keys[0..i] are the sorted voxel indices so far. The targets only grow with i, so one forward
  // scan per axis finds them all (no lookup table).
  void Neighbours(const std::vector<uint64_t>& keys, size_t i, const int64_t d[3], int64_t out[3]) {
    for (int a = 0; a < 3; ++a) {
      out[a] = -1;
      if (d[a] == 0) continue;  // no neighbour inside the extent (x - 1 would wrap a row)
      const uint64_t target = keys[i] - steps_[a];
      size_t& j = next_[a];
      while (j < i && keys[j] < target) ++j;
      if (j < i && keys[j] == target) out[a] = static_cast<int64_t>(j);
    }
  }
  // `none`: the prediction without neighbours (mid-range).
  static uint8_t Predict(const uint8_t* channel, const int64_t nb[3], uint8_t none) {
    int sum = 0, n = 0;
    for (int a = 0; a < 3; ++a) {
      if (nb[a] >= 0) {
        sum += channel[nb[a]];
        ++n;
      }
    }
    return static_cast<uint8_t>(n == 0 ? none : (sum + n / 2) / n);
  }

 private:
  uint64_t steps_[3];
  size_t next_[3] = {0, 0, 0};
};

// The bit counts of the wire, named as their configuration keys; empty when both are in range.
std::string WireBitsProblem(const SubmapOptions& o) {
  if (o.wire_offset_bits < 1 || o.wire_offset_bits > 4) {
    return "wire_offset_bits " + std::to_string(o.wire_offset_bits) + " outside 1..4";
  }
  if (o.wire_intensity_bits < 1 || o.wire_intensity_bits > 8) {
    return "wire_intensity_bits " + std::to_string(o.wire_intensity_bits) + " outside 1..8";
  }
  return "";
}

Status CheckOptions(const SubmapOptions& o) {
  const auto bad = [](double v, double lo, double hi) { return !(v >= lo && v <= hi); };
  if (bad(o.cloud_resolution, 0.001, 10.0) || bad(o.octree_resolution, 0.001, 10.0)) {
    return DataLossError("submap resolutions out of range");
  }
  if (const std::string problem = WireBitsProblem(o); !problem.empty())
    return DataLossError("submap " + problem);
  if (bad(o.log_odds_hit, 0.0, 100.0) || bad(o.log_odds_miss, -100.0, 0.0) ||
      bad(o.log_odds_min, -100.0, 0.0) || bad(o.log_odds_max, 0.0, 100.0)) {
    return DataLossError("submap log-odds parameters out of range");
  }
  return Status::Ok();
}

}  // namespace

Status SubmapCodec::ValidateOctreeBinary(std::span<const uint8_t> data) {
  // Iterative walk: (depth of the node's children) per pending inner node, in stream order.
  std::vector<int> pending;
  size_t pos = 0;
  if (data.empty()) return Status::Ok();  // empty tree
  pending.push_back(1);
  while (!pending.empty()) {
    const int child_depth = pending.back();
    pending.pop_back();
    if (pos + 2 > data.size()) return DataLossError("octree data ends inside a node at byte " + std::to_string(pos));
    const uint16_t bits = static_cast<uint16_t>(data[pos] | (data[pos + 1] << 8));
    pos += 2;
    int inner = 0;
    for (int i = 0; i < 8; ++i) inner += ((bits >> (2 * i)) & 3) == 3;
    if (inner > 0 && child_depth >= kTreeDepth) {
      return DataLossError("octree node at byte " + std::to_string(pos - 2) + " has children below the finest level");
    }
    // Children are read depth-first in order: push in reverse so the first is processed next.
    for (int i = 0; i < inner; ++i) pending.push_back(child_depth + 1);
  }
  if (pos != data.size()) {
    return DataLossError("octree data has " + std::to_string(data.size() - pos) + " trailing bytes");
  }
  return Status::Ok();
}

Expected<std::vector<uint8_t>> SubmapCodec::Encode(const Submap& submap, Compression compression,
                                                   uint16_t version) {
  if (version < kOldestVersion || version > kVersion)
    return InvalidArgumentError("submap format version " + std::to_string(version) + " cannot be written");
  const SubmapMetadata& m = submap.metadata();
  if (m.robot.size() > 255) return InvalidArgumentError("submap robot name longer than 255 bytes");
  if (const std::string problem = WireBitsProblem(m.options); !problem.empty()) {
    return InvalidArgumentError("submap " + problem);
  }
  ByteWriter w;
  w.U8(static_cast<uint8_t>(m.robot.size()));
  w.Bytes(std::span(reinterpret_cast<const uint8_t*>(m.robot.data()), m.robot.size()));
  w.U64(m.id);
  w.U64(static_cast<uint64_t>(m.start.nanoseconds()));
  w.U64(static_cast<uint64_t>(m.end.nanoseconds()));
  w.U32(m.images);
  F64(w, m.distance);
  F64(w, m.options.cloud_resolution);
  F64(w, m.options.octree_resolution);
  F64(w, m.options.log_odds_hit);
  F64(w, m.options.log_odds_miss);
  F64(w, m.options.log_odds_min);
  F64(w, m.options.log_odds_max);
  w.U8(static_cast<uint8_t>(m.options.wire_offset_bits));
  w.U8(static_cast<uint8_t>(m.options.wire_intensity_bits));

  // Cloud: voxel index and in-voxel offset of every point, sorted by index.
  const std::vector<CloudPoint>& pts = submap.points();
  const double res = m.options.cloud_resolution;
  const int offset_bits = static_cast<int>(m.options.wire_offset_bits);
  const int steps = 1 << offset_bits;
  const int drop = 8 - static_cast<int>(m.options.wire_intensity_bits);
  struct Q {
    uint64_t linear;
    int64_t d[3];  // cell in the extent
    uint8_t off[3];
    const CloudPoint* p;
  };
  Eigen::Vector3i lo = Eigen::Vector3i::Constant(INT32_MAX), hi = Eigen::Vector3i::Constant(INT32_MIN);
  std::vector<Eigen::Vector3i> cells(pts.size());
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3d c = (pts[i].p.cast<double>() / res).array().floor();
    if (!(c.array().abs() < 1e9).all()) return InvalidArgumentError("submap point not finite or too far away");
    cells[i] = c.cast<int>();
    lo = lo.cwiseMin(cells[i]);
    hi = hi.cwiseMax(cells[i]);
  }
  const Eigen::Vector3i extent = pts.empty() ? Eigen::Vector3i::Zero() : Eigen::Vector3i(hi - lo + Eigen::Vector3i::Ones());
  if ((extent.cast<double>().prod()) > 1e18) return InvalidArgumentError("submap cloud extent too large");
  std::vector<Q> q(pts.size());
  bool color = false;
  for (size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3i d = cells[i] - lo;
    for (int a = 0; a < 3; ++a) q[i].d[a] = d[a];
    q[i].linear = (static_cast<uint64_t>(d.z()) * static_cast<uint64_t>(extent.y()) + static_cast<uint64_t>(d.y())) *
                      static_cast<uint64_t>(extent.x()) + static_cast<uint64_t>(d.x());
    for (int a = 0; a < 3; ++a) {
      const double f = pts[i].p[a] / res - cells[i][a];
      q[i].off[a] = static_cast<uint8_t>(std::clamp(static_cast<int>(f * steps), 0, steps - 1));
    }
    q[i].p = &pts[i];
    color |= pts[i].r != pts[i].g || pts[i].r != pts[i].b;
  }
  std::sort(q.begin(), q.end(), [](const Q& a, const Q& b) { return a.linear < b.linear; });
  w.U32(static_cast<uint32_t>(q.size()));
  w.U8(color ? 1 : 0);
  for (int a = 0; a < 3; ++a) w.U32(static_cast<uint32_t>(lo[a]));
  for (int a = 0; a < 3; ++a) w.U32(static_cast<uint32_t>(extent[a]));
  std::vector<uint8_t> stream;
  uint64_t prev = 0;
  for (size_t i = 0; i < q.size(); ++i) {
    Varint(stream, i == 0 ? q[i].linear : q[i].linear - prev);
    prev = q[i].linear;
  }
  w.U32(static_cast<uint32_t>(stream.size()));
  // Each stream is compressed on its own (sections): their statistics differ too much to share
  // one entropy coder (one zstd frame over all of them is about 10 % larger).
  std::vector<size_t> cuts = {0, w.size()};
  w.Bytes(stream);
  cuts.push_back(w.size());
  // Separate streams per field compress far better than interleaved records; up to 2 bits per
  // axis one byte holds all three offsets.
  if (3 * offset_bits <= 8) {
    for (const Q& e : q)
      w.U8(static_cast<uint8_t>(e.off[0] | (e.off[1] << offset_bits) | (e.off[2] << (2 * offset_bits))));
  } else {
    for (const Q& e : q) w.U8(static_cast<uint8_t>(e.off[0] | (e.off[1] << 4)));
    cuts.push_back(w.size());
    for (const Q& e : q) w.U8(e.off[2]);
  }
  cuts.push_back(w.size());
  // Channels as residuals of their prediction (the decoder predicts from what it decoded).
  const int channels = color ? 3 : 1;
  std::vector<uint8_t> values(static_cast<size_t>(channels) * q.size()), residuals(values.size());
  for (size_t i = 0; i < q.size(); ++i) {
    values[i] = static_cast<uint8_t>(q[i].p->r >> drop);
    if (color) {
      values[q.size() + i] = static_cast<uint8_t>(q[i].p->g >> drop);
      values[2 * q.size() + i] = static_cast<uint8_t>(q[i].p->b >> drop);
    }
  }
  ChannelPredictor predictor(extent);
  std::vector<uint64_t> keys(q.size());
  for (size_t i = 0; i < q.size(); ++i) keys[i] = q[i].linear;
  for (size_t i = 0; i < q.size(); ++i) {
    int64_t nb[3];
    predictor.Neighbours(keys, i, q[i].d, nb);
    for (int c = 0; c < channels; ++c) {
      const uint8_t* channel = values.data() + c * q.size();
      residuals[c * q.size() + i] =
          static_cast<uint8_t>(channel[i] - ChannelPredictor::Predict(channel, nb, 128 >> drop));
    }
  }
  w.Bytes(residuals);
  cuts.push_back(w.size());
  std::vector<uint8_t> bits((q.size() + 7) / 8, 0);
  for (size_t i = 0; i < q.size(); ++i) {
    if (q[i].p->obstacle) bits[i / 8] |= static_cast<uint8_t>(1u << (i % 8));
  }
  w.Bytes(bits);
  cuts.push_back(w.size());
  const std::string tree = TreeBinary(submap.tree());
  w.U64(tree.size());
  w.Bytes(std::span(reinterpret_cast<const uint8_t*>(tree.data()), tree.size()));
  if (version >= 4) {
    cuts.push_back(w.size());
    WriteStructure(submap.structure(), version, w);
  }

  cuts.push_back(w.size());
  if (w.size() > kMaxPayload)
    return InvalidArgumentError("submap larger than " + std::to_string(kMaxPayload) + " bytes");
  // Body: section count, (raw size, packed size) per section, then the packed sections.
  ByteWriter body;
  body.U8(static_cast<uint8_t>(cuts.size() - 1));
  std::vector<std::vector<uint8_t>> packed(cuts.size() - 1);
  for (size_t i = 0; i + 1 < cuts.size(); ++i) {
    const std::span<const uint8_t> section(w.buffer().data() + cuts[i], cuts[i + 1] - cuts[i]);
    CAIRN_RETURN_IF_ERROR(Compressor::Compress(compression, section, &packed[i], kZstdLevel));
    body.U32(static_cast<uint32_t>(section.size()));
    body.U32(static_cast<uint32_t>(packed[i].size()));
  }
  for (const std::vector<uint8_t>& p : packed) body.Bytes(p);
  const std::vector<uint8_t>& compressed = body.buffer();
  ByteWriter out;
  out.Bytes(std::span(reinterpret_cast<const uint8_t*>(kMagic), sizeof(kMagic)));
  out.U16(version);
  out.U8(static_cast<uint8_t>(compression));
  out.U8(0);
  out.U64(w.size());
  out.U64(compressed.size());
  out.U32(Crc32::Of(w.buffer()));
  out.U32(Crc32::Of(compressed));
  out.Bytes(compressed);
  return std::move(out.buffer());
}

Expected<std::shared_ptr<const Submap>> SubmapCodec::Decode(std::span<const uint8_t> bytes) {
  ByteReader h(bytes);
  const auto magic = h.Take(sizeof(kMagic));
  if (h.failed() || std::memcmp(magic.data(), kMagic, sizeof(kMagic)) != 0) {
    return DataLossError("not a cairn submap (bad magic)");
  }
  const uint16_t version = h.U16();
  const uint8_t compression = h.U8();
  const uint8_t reserved = h.U8();
  const uint64_t raw_size = h.U64();
  const uint64_t packed_size = h.U64();
  const uint32_t raw_crc = h.U32();
  const uint32_t packed_crc = h.U32();
  if (h.failed()) return DataLossError("submap header truncated");
  if (version < kOldestVersion || version > kVersion) {
    return DataLossError("submap format version " + std::to_string(version) + " is not supported (" +
                         std::to_string(kOldestVersion) + " to " + std::to_string(kVersion) + ")");
  }
  if (reserved != 0) return DataLossError("submap header reserved byte is " + std::to_string(reserved));
  if (compression > static_cast<uint8_t>(Compression::kLz4)) return DataLossError("submap has unknown compression " + std::to_string(compression));
  if (raw_size > kMaxPayload) return DataLossError("submap payload size " + std::to_string(raw_size) + " is implausible");
  if (packed_size != h.remaining()) {
    return DataLossError("submap body is " + std::to_string(h.remaining()) + " bytes, header says " + std::to_string(packed_size));
  }
  const auto packed = h.Take(packed_size);
  if (Crc32::Of(packed) != packed_crc) return DataLossError("submap checksum mismatch (compressed body)");
  ByteReader sections(packed);
  const uint8_t count = sections.U8();
  if (sections.failed() || count == 0 || count > kMaxSections) {
    return DataLossError("submap body has " + std::to_string(count) + " sections (1.." +
                         std::to_string(kMaxSections) + ")");
  }
  std::vector<std::pair<uint32_t, uint32_t>> table(count);
  uint64_t raw_total = 0, packed_total = 0;
  for (auto& [raw_bytes, packed_bytes] : table) {
    raw_bytes = sections.U32();
    packed_bytes = sections.U32();
    raw_total += raw_bytes;
    packed_total += packed_bytes;
  }
  if (sections.failed() || raw_total != raw_size || packed_total != sections.remaining()) {
    return DataLossError("submap section table does not match the body");
  }
  std::vector<uint8_t> raw, section;
  raw.reserve(raw_size);
  for (size_t i = 0; i < table.size(); ++i) {
    const Status st = Compressor::Decompress(static_cast<Compression>(compression),
                                             sections.Take(table[i].second), table[i].first, &section);
    if (!st.ok())
      return DataLossError("submap section " + std::to_string(i) + " does not decompress: " + st.message());
    raw.insert(raw.end(), section.begin(), section.end());
  }
  if (Crc32::Of(raw) != raw_crc) return DataLossError("submap checksum mismatch (payload)");

  ByteReader r(raw);
  SubmapMetadata m;
  const auto name = r.Take(r.U8());
  m.robot.assign(name.begin(), name.end());
  m.id = r.U64();
  m.start = Timestamp::FromNanoseconds(static_cast<int64_t>(r.U64()));
  m.end = Timestamp::FromNanoseconds(static_cast<int64_t>(r.U64()));
  m.images = r.U32();
  m.distance = F64(r);
  m.options.cloud_resolution = F64(r);
  m.options.octree_resolution = F64(r);
  m.options.log_odds_hit = F64(r);
  m.options.log_odds_miss = F64(r);
  m.options.log_odds_min = F64(r);
  m.options.log_odds_max = F64(r);
  m.options.wire_offset_bits = r.U8();
  m.options.wire_intensity_bits = r.U8();
  if (r.failed()) return DataLossError("submap metadata truncated");
  if (!(m.distance >= 0.0 && std::isfinite(m.distance))) return DataLossError("submap distance is invalid");
  CAIRN_RETURN_IF_ERROR(CheckOptions(m.options));

  const uint32_t n = r.U32();
  const uint8_t color = r.U8();
  Eigen::Vector3i lo, extent;
  for (int a = 0; a < 3; ++a) lo[a] = static_cast<int32_t>(r.U32());
  for (int a = 0; a < 3; ++a) extent[a] = static_cast<int32_t>(r.U32());
  if (r.failed()) return DataLossError("submap cloud header truncated");
  if (color > 1) return DataLossError("submap cloud colour flag is " + std::to_string(color));
  const int offset_bits = static_cast<int>(m.options.wire_offset_bits);
  const int steps = 1 << offset_bits;
  const bool packed_offsets = 3 * offset_bits <= 8;
  const int drop = 8 - static_cast<int>(m.options.wire_intensity_bits);
  const uint64_t per_point = (color ? 3 : 1) + (packed_offsets ? 1 : 2);
  if (static_cast<uint64_t>(n) * per_point > r.remaining()) return DataLossError("submap cloud count " + std::to_string(n) + " exceeds the data");
  if (n > 0 && (extent.minCoeff() <= 0 || extent.cast<double>().prod() > 1e18)) return DataLossError("submap cloud extent is invalid");
  ByteReader keys(r.Take(r.U32()));
  const auto xy = r.Take(n), z = packed_offsets ? xy : r.Take(n);
  const int channels = color ? 3 : 1;
  const auto coded = r.Take(static_cast<uint64_t>(channels) * n);
  const auto bits = r.Take((static_cast<uint64_t>(n) + 7) / 8);
  if (r.failed()) return DataLossError("submap cloud streams truncated");
  const uint64_t cells = static_cast<uint64_t>(extent.x()) * static_cast<uint64_t>(extent.y()) * static_cast<uint64_t>(extent.z());
  std::vector<CloudPoint> pts(n);
  const double res = m.options.cloud_resolution;
  // The channels' residuals, turned into values in decoding order as the encoder predicted them.
  std::vector<uint8_t> values(coded.begin(), coded.end());
  ChannelPredictor predictor(extent);
  std::vector<uint64_t> decoded_keys;
  decoded_keys.reserve(n);
  uint64_t linear = 0;
  for (uint32_t i = 0; i < n; ++i) {
    uint64_t d;
    if (!Varint(keys, &d)) return DataLossError("submap point " + std::to_string(i) + ": voxel index stream truncated");
    // A zero step is a second point in the same voxel: float rounding can put a centroid computed
    // in one voxel on the boundary of the next, and both points are kept as they were.
    linear += d;
    if (linear >= cells || linear < d) return DataLossError("submap point " + std::to_string(i) + ": voxel index outside the extent");
    int o[3];
    if (packed_offsets) {
      for (int a = 0; a < 3; ++a) o[a] = (xy[i] >> (a * offset_bits)) & (steps - 1);
      if ((xy[i] >> (3 * offset_bits)) != 0)
        return DataLossError("submap point " + std::to_string(i) + ": offset out of range");
    } else {
      o[0] = xy[i] & 0xF;
      o[1] = xy[i] >> 4;
      o[2] = z[i];
      if (o[0] >= steps || o[1] >= steps || o[2] >= steps)
        return DataLossError("submap point " + std::to_string(i) + ": offset out of range");
    }
    const int64_t x = static_cast<int64_t>(linear % static_cast<uint64_t>(extent.x()));
    const int64_t y = static_cast<int64_t>((linear / static_cast<uint64_t>(extent.x())) % static_cast<uint64_t>(extent.y()));
    const int64_t zz = static_cast<int64_t>(linear / (static_cast<uint64_t>(extent.x()) * static_cast<uint64_t>(extent.y())));
    const double off[3] = {o[0] + 0.5, o[1] + 0.5, o[2] + 0.5};
    const int64_t cell[3] = {x, y, zz};
    int64_t nb[3];
    decoded_keys.push_back(linear);
    predictor.Neighbours(decoded_keys, i, cell, nb);
    for (int c = 0; c < channels; ++c) {
      uint8_t* channel = values.data() + static_cast<size_t>(c) * n;
      channel[i] = static_cast<uint8_t>(channel[i] + ChannelPredictor::Predict(channel, nb, 128 >> drop));
      if ((channel[i] >> (8 - drop)) != 0) {
        return DataLossError("submap point " + std::to_string(i) + ": intensity or colour out of range");
      }
    }
    CloudPoint& p = pts[i];
    p.p = Eigen::Vector3f(static_cast<float>((lo.x() + x + off[0] / steps) * res),
                          static_cast<float>((lo.y() + y + off[1] / steps) * res),
                          static_cast<float>((lo.z() + zz + off[2] / steps) * res));
    // Each value comes back at the middle of its quantization step.
    const auto value = [&](size_t k) {
      return static_cast<uint8_t>((values[k] << drop) | ((1 << drop) >> 1));
    };
    p.r = value(i);
    p.g = value((color ? n : 0) + i);
    p.b = value((color ? 2 * static_cast<size_t>(n) : 0) + i);
    p.obstacle = (bits[i / 8] >> (i % 8)) & 1;
  }
  if (keys.remaining() != 0) return DataLossError("submap voxel index stream has trailing bytes");
  const uint64_t tree_size = r.U64();
  if (r.failed() || (version >= 4 ? tree_size > r.remaining() : tree_size != r.remaining()))
    return DataLossError("submap octree size does not match the data");
  const auto tree_bytes = r.Take(tree_size);
  SubmapStructure structure;
  if (version >= 4) CAIRN_RETURN_IF_ERROR(ReadStructure(r, version, &structure));
  CAIRN_RETURN_IF_ERROR(ValidateOctreeBinary(tree_bytes).WithContext("submap octree"));
  auto tree = MakeOccupancyTree(m.options);
  if (!tree_bytes.empty()) {
    std::istringstream s(std::string(reinterpret_cast<const char*>(tree_bytes.data()), tree_bytes.size()));
    tree->readBinaryData(s);
    if (!s) return DataLossError("submap octree does not parse");
  }
  return std::make_shared<const Submap>(std::move(m), std::move(pts), std::move(tree), std::move(structure));
}

Expected<std::shared_ptr<const Submap>> SubmapCodec::ReadFile(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  if (!f) return NotFoundError("cannot open submap " + path);
  std::vector<uint8_t> bytes((std::istreambuf_iterator<char>(f)), std::istreambuf_iterator<char>());
  auto s = Decode(bytes);
  if (!s.ok()) return s.status().WithContext(path);
  return s;
}

}  // namespace cairn
