#pragma once
// Every robot's items on disk, durable: one append-only log per (origin robot, lane), numbered
// 1, 2, 3... without gaps, so that a high-water mark says exactly what is held and peers only
// compare marks to know what to send. An append returns Ok only once the item is on disk
// (fdatasync; a new log is created whole by rename and its folder synced), so whatever the
// exchange announces or acknowledges survives a crash. At open every log is read back: a torn or
// corrupt tail (a crash mid-write, a bad block) is cut off and reported, and the items lost with
// it come again from the teammates; a file that is not an item log stops the open instead.
//
// <dir>/<origin>.<lane>.log: file magic u32, format version u32, then records of
// magic u32, seq u64, kind u16, payload length u32, payload, CRC-32 of all before it in the
// record (little endian). The index keeps 16 bytes per item, never payloads. Not thread safe: the
// comms thread owns it.

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "common/status.h"

namespace cairn {

struct ItemKey {
  std::string origin;  // robot name: [A-Za-z0-9_-]{1,32}
  uint8_t lane = 0;    // below ItemStore::kMaxLanes
  uint64_t seq = 0;    // from 1
};

struct StoreItem {
  ItemKey key;
  uint16_t kind = 0;
  std::string payload;
};

// What a sender needs to prioritise without reading the payload.
struct ItemInfo {
  uint16_t kind = 0;
  uint64_t size = 0;  // payload bytes
};

struct ItemStoreOptions {
  uint64_t max_item_bytes = 16 << 20;  // payload; at most 4 GiB - 1 whatever is set
  bool fsync = true;  // off only in tests that measure nothing about durability
};

// A log repaired at open.
struct ItemStoreRecovery {
  std::string file;
  uint64_t valid_items = 0;    // kept, 1..valid_items
  uint64_t offset = 0;         // byte where the file was cut
  uint64_t dropped_bytes = 0;
  std::string reason;
};

struct ItemStoreCounters {
  uint64_t appended = 0;
  uint64_t duplicates = 0;  // appends of items held already
  uint64_t gaps = 0;        // appends that would leave a gap
  uint64_t io_errors = 0;   // appends the disk refused
};

class ItemStore {
 public:
  static constexpr uint8_t kMaxLanes = 4;

  // Creates `dir` when missing and reads every <origin>.<lane>.log in it; other files are left
  // alone. Fails, naming the file, on a log this code did not write (foreign magic or version).
  static Expected<std::unique_ptr<ItemStore>> Open(const std::string& dir, const ItemStoreOptions& options);
  ~ItemStore();
  ItemStore(const ItemStore&) = delete;
  ItemStore& operator=(const ItemStore&) = delete;

  // Durable when Ok. kInvalidArgument for a bad origin, lane, seq 0 or an oversized payload;
  // kAlreadyExists for a held item (seq <= mark); kFailedPrecondition for a gap (seq > mark + 1);
  // kIoError when the disk fails (ENOSPC, EFBIG, EIO): the log is cut back to its last whole
  // record and stays usable.
  Status Append(const StoreItem& item);

  uint64_t HighWaterMark(const std::string& origin, uint8_t lane) const;  // 0 when none
  // Lanes holding at least one item.
  std::map<std::pair<std::string, uint8_t>, uint64_t> HighWaterMarks() const;

  // Reads the record back from the file and checks it again: kNotFound when not held, kDataLoss
  // (file and byte offset) when the disk changed under the store.
  Expected<StoreItem> Read(const ItemKey& key) const;
  // From the index, no disk access.
  Expected<ItemInfo> Info(const ItemKey& key) const;

  const std::string& dir() const { return dir_; }
  const std::vector<ItemStoreRecovery>& recoveries() const { return recoveries_; }
  const ItemStoreCounters& counters() const { return counters_; }

  static bool ValidOrigin(const std::string& origin);

 private:
  struct Entry {
    uint64_t offset = 0;  // of the record
    uint32_t size = 0;    // payload bytes
    uint16_t kind = 0;
  };
  static_assert(sizeof(Entry) == 16, "the index stays at 16 bytes per item");
  struct Log {
    ~Log();
    std::string path;
    int fd = -1;
    uint64_t end = 0;    // of the last whole record: where the next one goes
    bool dirty = false;  // a failed append could not be cut back yet
    std::vector<Entry> entries;  // entries[i] is seq i + 1
  };
  using LogId = std::pair<std::string, uint8_t>;

  ItemStore(std::string dir, const ItemStoreOptions& options);
  Status Load(const LogId& id, const std::string& path);
  Status Scan(Log& log, uint64_t size);
  Expected<Log*> Create(const LogId& id);
  Status CutBack(Log& log);
  const Log* Find(const ItemKey& key) const;

  std::string dir_;
  ItemStoreOptions options_;
  uint64_t max_payload_;
  std::map<LogId, std::unique_ptr<Log>> logs_;
  std::vector<ItemStoreRecovery> recoveries_;
  ItemStoreCounters counters_;
};

}  // namespace cairn
