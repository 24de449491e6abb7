#include "daemon/comms/item_assembler.h"

#include <algorithm>

namespace cairn {

uint64_t ItemAssembler::CoveredPrefix(const Partial& p) {
  uint64_t covered = 0;
  for (const auto& [offset, data] : p.pieces) {
    if (offset > covered) break;
    covered = std::max<uint64_t>(covered, offset + data.size());
  }
  return covered;
}

void ItemAssembler::Erase(std::map<Key, Partial>::iterator it) {
  bytes_ -= it->second.bytes;
  partials_.erase(it);
}

ItemAssembler::Outcome ItemAssembler::Add(const Key& key, const Piece& piece) {
  Outcome out;
  const std::string& data = *piece.data;
  auto it = partials_.find(key);
  if (it != partials_.end() &&
      (it->second.kind != piece.kind || it->second.crc != piece.crc || it->second.total != piece.total)) {
    // Two versions of one item: one sender is wrong; start again with the newer pieces.
    out.conflict = true;
    Erase(it);
    it = partials_.end();
  }
  if (it == partials_.end()) {
    if (bytes_ + data.size() > max_bytes_) {
      out.full = true;
      return out;
    }
    Partial p;
    p.kind = piece.kind;
    p.crc = piece.crc;
    p.total = piece.total;
    it = partials_.emplace(key, std::move(p)).first;
  }
  Partial& p = it->second;
  // Senders cut items differently (their fragment size, a resend resuming mid-item): a longer
  // piece at the same offset replaces the shorter one.
  const auto [held, inserted] = p.pieces.emplace(piece.offset, data);
  if (inserted) {
    p.bytes += data.size();
    bytes_ += data.size();
  } else if (held->second.size() < data.size()) {
    p.bytes += data.size() - held->second.size();
    bytes_ += data.size() - held->second.size();
    held->second = data;
  }
  if (CoveredPrefix(p) < p.total) return out;
  out.payload.reserve(p.total);
  for (const auto& [offset, bytes] : p.pieces) {
    if (offset + bytes.size() <= out.payload.size()) continue;
    out.payload.append(bytes, out.payload.size() - offset, std::string::npos);
  }
  out.complete = true;
  out.kind = p.kind;
  out.crc = p.crc;
  Erase(it);
  return out;
}

std::vector<std::pair<ItemAssembler::Key, uint64_t>> ItemAssembler::Prefixes() const {
  std::vector<std::pair<Key, uint64_t>> out;
  for (const auto& [key, p] : partials_) {
    if (const uint64_t covered = CoveredPrefix(p); covered > 0) out.emplace_back(key, covered);
  }
  return out;
}

}  // namespace cairn
