#pragma once
// Items that travel in pieces, reassembled on arrival: pieces by offset, from any round and any
// peer, in any order, repeats free. Bounded in bytes; what an item's first pieces hold without a
// gap is what a summary tells the senders, so that a resend resumes there.

#include <cstdint>
#include <map>
#include <optional>
#include <string>
#include <tuple>
#include <vector>

namespace cairn {

class ItemAssembler {
 public:
  using Key = std::tuple<std::string, uint8_t, uint64_t>;  // origin, lane, seq

  struct Piece {
    uint16_t kind = 0;
    uint32_t crc = 0;    // of the whole payload, as the sender states it
    uint32_t total = 0;  // payload bytes
    uint32_t offset = 0;
    const std::string* data = nullptr;  // offset + size <= total, checked by the caller
  };
  struct Outcome {
    bool conflict = false;  // pieces of another version were held: dropped, this one kept
    bool full = false;      // no room for a new item: the piece is dropped
    bool complete = false;  // `payload` holds the item (its CRC not checked here)
    uint16_t kind = 0;
    uint32_t crc = 0;
    std::string payload;
  };

  explicit ItemAssembler(uint64_t max_bytes) : max_bytes_(max_bytes) {}

  Outcome Add(const Key& key, const Piece& piece);
  // Items in pieces whose first bytes are held, in key order, with how many.
  std::vector<std::pair<Key, uint64_t>> Prefixes() const;
  uint64_t bytes() const { return bytes_; }
  size_t items() const { return partials_.size(); }

 private:
  struct Partial {
    uint16_t kind = 0;
    uint32_t crc = 0;
    uint32_t total = 0;
    std::map<uint32_t, std::string> pieces;
    uint64_t bytes = 0;
  };

  static uint64_t CoveredPrefix(const Partial& p);
  void Erase(std::map<Key, Partial>::iterator it);

  uint64_t max_bytes_;
  uint64_t bytes_ = 0;
  std::map<Key, Partial> partials_;
};

}  // namespace cairn
