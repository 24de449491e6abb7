#include "sim/candump_format.h"

#include <cinttypes>
#include <cstdio>
#include <cstdlib>

namespace cairn::sim {
namespace {

int HexDigit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  return -1;
}

}  // namespace

std::string FormatCandumpLine(Timestamp time, const std::string& interface, const can_frame& frame) {
  const int64_t us = (time.nanoseconds() + 500) / 1000;
  char head[64];
  const bool extended = (frame.can_id & CAN_EFF_FLAG) != 0;
  std::snprintf(head, sizeof(head), extended ? "(%" PRId64 ".%06" PRId64 ") %s %08X#" : "(%" PRId64 ".%06" PRId64 ") %s %03X#",
                us / 1000000, us % 1000000, interface.c_str(),
                static_cast<unsigned>(frame.can_id & (extended ? CAN_EFF_MASK : CAN_SFF_MASK)));
  std::string line = head;
  static const char kHex[] = "0123456789ABCDEF";
  for (int i = 0; i < frame.len; ++i) {
    line += kHex[frame.data[i] >> 4];
    line += kHex[frame.data[i] & 15];
  }
  return line;
}

Expected<CandumpRecord> ParseCandumpLine(const std::string& line) {
  CandumpRecord r;
  const size_t close = line.find(')');
  const size_t dot = line.find('.');
  if (line.empty() || line[0] != '(' || close == std::string::npos || dot == std::string::npos || dot > close) {
    return DataLossError("expected '(seconds.microseconds) interface id#data'");
  }
  char* end = nullptr;
  const long long sec = std::strtoll(line.c_str() + 1, &end, 10);
  if (end != line.c_str() + dot) return DataLossError("bad seconds in timestamp");
  const long long usec = std::strtoll(line.c_str() + dot + 1, &end, 10);
  if (end != line.c_str() + close || close - dot - 1 != 6) return DataLossError("timestamp needs 6 microsecond digits");
  // int64 nanoseconds reach the year 2262; a sign or more digits is not a time.
  if (sec < 0 || sec > 9000000000LL || usec < 0) return DataLossError("timestamp out of range");
  r.time = Timestamp::FromNanoseconds(sec * 1000000000LL + usec * 1000LL);
  const size_t if_begin = line.find_first_not_of(' ', close + 1);
  const size_t if_end = line.find(' ', if_begin);
  if (if_begin == std::string::npos || if_end == std::string::npos) return DataLossError("missing interface");
  r.interface = line.substr(if_begin, if_end - if_begin);
  const size_t hash = line.find('#', if_end);
  if (hash == std::string::npos) return DataLossError("missing '#' between id and data");
  const std::string id = line.substr(if_end + 1, hash - if_end - 1);
  if (id.empty() || (id.size() != 3 && id.size() != 8)) return DataLossError("id must have 3 or 8 hex digits");
  uint32_t idv = 0;
  for (char c : id) {
    const int d = HexDigit(c);
    if (d < 0) return DataLossError("id is not hexadecimal");
    idv = idv * 16 + static_cast<uint32_t>(d);
  }
  r.frame.can_id = idv | (id.size() == 8 ? CAN_EFF_FLAG : 0u);
  std::string data = line.substr(hash + 1);
  while (!data.empty() && (data.back() == '\r' || data.back() == ' ')) data.pop_back();
  if (data.size() % 2 != 0 || data.size() > 16) return DataLossError("data must be 0-8 bytes in hex pairs");
  for (size_t i = 0; i < data.size(); i += 2) {
    const int hi = HexDigit(data[i]), lo = HexDigit(data[i + 1]);
    if (hi < 0 || lo < 0) return DataLossError("data is not hexadecimal");
    r.frame.data[i / 2] = static_cast<uint8_t>(hi * 16 + lo);
  }
  r.frame.len = static_cast<uint8_t>(data.size() / 2);
  return r;
}

}  // namespace cairn::sim
