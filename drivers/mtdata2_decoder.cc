#include "drivers/mtdata2_decoder.h"

#include <cmath>
#include <cstdio>
#include <cstring>
#include <string>

namespace cairn {
namespace {

std::string Hex(uint16_t xdi) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", xdi);
  return buf;
}

uint32_t BigEndian32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) << 24 | static_cast<uint32_t>(p[1]) << 16 | static_cast<uint32_t>(p[2]) << 8 | p[3];
}

uint64_t BigEndian64(const uint8_t* p) {
  return static_cast<uint64_t>(BigEndian32(p)) << 32 | BigEndian32(p + 4);
}

// Three values of `format` (the XDI's low two bits) from `data` of `size` bytes.
Status ReadVector(uint16_t xdi, const uint8_t* data, size_t size, Eigen::Vector3d* out) {
  const int format = xdi & 0x3;
  if ((xdi & 0xC) != 0)
    return FailedPreconditionError("MTData2 " + Hex(xdi) +
                                   ": coordinates other than the sensor's own (configure the default, ENU)");
  if (format == 2) return FailedPreconditionError("MTData2 " + Hex(xdi) + ": fixed-point 16.32 is not supported (configure float32)");
  const size_t width = format == 3 ? 8 : 4;
  if (size != 3 * width)
    return DataLossError("MTData2 " + Hex(xdi) + " has " + std::to_string(size) + " bytes, expected " +
                         std::to_string(3 * width));
  for (int i = 0; i < 3; ++i) {
    const uint8_t* p = data + static_cast<size_t>(i) * width;
    double v = 0.0;
    if (format == 0) {
      const uint32_t bits = BigEndian32(p);
      float f;
      std::memcpy(&f, &bits, sizeof f);
      v = f;
    } else if (format == 1) {
      v = static_cast<int32_t>(BigEndian32(p)) / 1048576.0;  // 12.20 fixed point
    } else {
      const uint64_t bits = BigEndian64(p);
      std::memcpy(&v, &bits, sizeof v);
    }
    if (!std::isfinite(v)) return DataLossError("MTData2 " + Hex(xdi) + ": non-finite value");
    (*out)[i] = v;
  }
  return Status::Ok();
}

}  // namespace

Expected<Mtdata2Sample> Mtdata2Decoder::Decode(std::span<const uint8_t> payload) {
  Mtdata2Sample s;
  size_t p = 0;
  while (p < payload.size()) {
    if (payload.size() - p < 3)
      return DataLossError("MTData2 ends inside a packet header (" + std::to_string(payload.size() - p) + " bytes left)");
    const uint16_t xdi = static_cast<uint16_t>(payload[p] << 8 | payload[p + 1]);
    const size_t size = payload[p + 2];
    p += 3;
    if (payload.size() - p < size)
      return DataLossError("MTData2 " + Hex(xdi) + " declares " + std::to_string(size) + " bytes, " +
                           std::to_string(payload.size() - p) + " left");
    const uint8_t* data = payload.data() + p;
    p += size;
    const auto need = [&](size_t expected) -> Status {
      if (size == expected) return Status::Ok();
      return DataLossError("MTData2 " + Hex(xdi) + " has " + std::to_string(size) + " bytes, expected " +
                           std::to_string(expected));
    };
    switch (xdi & 0xFFF0) {
      case kPacketCounter:
        CAIRN_RETURN_IF_ERROR(need(2));
        s.has_counter = true;
        s.counter = static_cast<uint16_t>(data[0] << 8 | data[1]);
        break;
      case kSampleTimeFine:
        CAIRN_RETURN_IF_ERROR(need(4));
        s.has_sample_time = true;
        s.sample_time_fine = BigEndian32(data);
        break;
      case kAcceleration:
        CAIRN_RETURN_IF_ERROR(ReadVector(xdi, data, size, &s.acceleration));
        s.has_acceleration = true;
        break;
      case kRateOfTurn:
        CAIRN_RETURN_IF_ERROR(ReadVector(xdi, data, size, &s.rate_of_turn));
        s.has_rate_of_turn = true;
        break;
      case kStatusWord:
        CAIRN_RETURN_IF_ERROR(need(4));
        s.has_status = true;
        s.status = BigEndian32(data);
        break;
      default:
        ++s.skipped_packets;
        break;
    }
  }
  return s;
}

}  // namespace cairn
