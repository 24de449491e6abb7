#include "daemon/comms/item_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <sys/uio.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>

#include "io/byte_reader.h"
#include "io/byte_writer.h"
#include "io/crc32.h"

namespace cairn {
namespace {

constexpr uint32_t kFileMagic = 0x4c544943;    // "CITL" on disk
constexpr uint32_t kFormatVersion = 1;
constexpr uint32_t kRecordMagic = 0x52544943;  // "CITR" on disk
constexpr size_t kFileHeaderBytes = 4 + 4;
constexpr size_t kRecordHeaderBytes = 4 + 8 + 2 + 4;
constexpr size_t kCrcBytes = 4;

struct RecordHeader {
  uint32_t magic = 0;
  uint64_t seq = 0;
  uint16_t kind = 0;
  uint32_t size = 0;
};

RecordHeader DecodeHeader(const uint8_t (&bytes)[kRecordHeaderBytes]) {
  ByteReader r(bytes);
  RecordHeader h;
  h.magic = r.U32();
  h.seq = r.U64();
  h.kind = r.U16();
  h.size = r.U32();
  return h;
}

uint32_t DecodeU32(const uint8_t* bytes) { return ByteReader(std::span<const uint8_t>(bytes, 4)).U32(); }

std::string Hex(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof buf, "0x%08x", v);
  return buf;
}

std::string ErrnoText(int err) { return std::strerror(err); }

std::string KeyName(const ItemKey& k) {
  // The origin may come from a peer: keep the message short and printable.
  std::string origin = k.origin.substr(0, 40);
  for (char& c : origin) {
    if (static_cast<unsigned char>(c) < 0x20 || static_cast<unsigned char>(c) > 0x7e) c = '?';
  }
  return origin + "/" + std::to_string(k.lane) + "/" + std::to_string(k.seq);
}

enum class Transfer { kDone, kEnd, kError };

// Moves every byte of `iov` from or to `offset`: preadv and pwritev may do only part of it.
// kEnd: the file ended first (reads only). kError leaves errno set.
Transfer MoveAll(int fd, uint64_t offset, iovec* iov, int count, bool write) {
  while (count > 0) {
    if (iov->iov_len == 0) {
      ++iov;
      --count;
      continue;
    }
    const ssize_t n = write ? pwritev(fd, iov, count, static_cast<off_t>(offset))
                            : preadv(fd, iov, count, static_cast<off_t>(offset));
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) return Transfer::kError;
    if (n == 0) {
      if (!write) return Transfer::kEnd;
      errno = ENOSPC;
      return Transfer::kError;
    }
    offset += static_cast<uint64_t>(n);
    for (size_t done = static_cast<size_t>(n); done > 0;) {
      if (done >= iov->iov_len) {
        done -= iov->iov_len;
        ++iov;
        --count;
      } else {
        iov->iov_base = static_cast<uint8_t*>(iov->iov_base) + done;
        iov->iov_len -= done;
        done = 0;
      }
    }
  }
  return Transfer::kDone;
}

// Reads while opening, where a file shorter than fstat said is an error, not a torn tail.
Status ReadAt(const std::string& path, int fd, uint64_t offset, void* out, size_t n) {
  iovec iov{out, n};
  switch (MoveAll(fd, offset, &iov, 1, false)) {
    case Transfer::kDone:
      return Status::Ok();
    case Transfer::kEnd:
      return IoError(path + ": the file shrank under the store at byte " + std::to_string(offset));
    case Transfer::kError:
      break;
  }
  const int err = errno;
  return IoError(path + ": cannot read at byte " + std::to_string(offset) + ": " + ErrnoText(err));
}

Status SyncFolder(const std::string& dir) {
  const int fd = open(dir.c_str(), O_RDONLY | O_DIRECTORY | O_CLOEXEC);
  if (fd < 0) {
    const int err = errno;
    return IoError(dir + ": cannot open the folder to sync it: " + ErrnoText(err));
  }
  const int r = fsync(fd);
  const int err = errno;
  close(fd);
  return r == 0 ? Status::Ok() : IoError(dir + ": cannot sync the folder: " + ErrnoText(err));
}

// <origin>.<lane>.log with a valid origin and lane; anything else is not a log of this store.
bool ParseLogName(const std::string& name, std::pair<std::string, uint8_t>& id) {
  const std::string suffix = ".log";
  if (name.size() < suffix.size() + 3 || name.compare(name.size() - suffix.size(), suffix.size(), suffix) != 0)
    return false;
  const std::string stem = name.substr(0, name.size() - suffix.size());
  const char lane = stem.back();
  if (stem[stem.size() - 2] != '.' || lane < '0' || lane >= '0' + ItemStore::kMaxLanes) return false;
  id.first = stem.substr(0, stem.size() - 2);
  id.second = static_cast<uint8_t>(lane - '0');
  return ItemStore::ValidOrigin(id.first);
}

}  // namespace

ItemStore::Log::~Log() {
  if (fd >= 0) close(fd);
}

ItemStore::ItemStore(std::string dir, const ItemStoreOptions& options)
    : dir_(std::move(dir)),
      options_(options),
      max_payload_(std::min<uint64_t>(options.max_item_bytes, std::numeric_limits<uint32_t>::max())) {}

ItemStore::~ItemStore() = default;

bool ItemStore::ValidOrigin(const std::string& origin) {
  if (origin.empty() || origin.size() > 32) return false;
  return std::all_of(origin.begin(), origin.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' || c == '-';
  });
}

Expected<std::unique_ptr<ItemStore>> ItemStore::Open(const std::string& dir, const ItemStoreOptions& options) {
  namespace fs = std::filesystem;
  std::string root = dir;
  while (root.size() > 1 && root.back() == '/') root.pop_back();
  std::error_code ec;
  const bool created = fs::create_directories(root, ec);
  if (ec) return IoError(root + ": cannot create the item store folder: " + ec.message());
  if (!fs::is_directory(root, ec)) return IoError(root + ": the item store is not a folder");
  if (created && options.fsync) {
    // The folder's own entry, or the first log synced into it could vanish with it.
    CAIRN_RETURN_IF_ERROR(SyncFolder((fs::path(root) / "..").lexically_normal().string()));
  }

  std::vector<std::pair<LogId, std::string>> found;
  fs::directory_iterator it(root, ec);
  for (; !ec && it != fs::directory_iterator(); it.increment(ec)) {
    LogId id;
    std::error_code type_ec;
    if (!ParseLogName(it->path().filename().string(), id) || !it->is_regular_file(type_ec)) continue;
    found.emplace_back(std::move(id), it->path().string());
  }
  if (ec) return IoError(root + ": cannot list the item store folder: " + ec.message());
  std::sort(found.begin(), found.end());  // recoveries in a stable order

  std::unique_ptr<ItemStore> store(new ItemStore(root, options));
  for (const auto& [id, path] : found) CAIRN_RETURN_IF_ERROR(store->Load(id, path));
  return store;
}

Status ItemStore::Load(const LogId& id, const std::string& path) {
  auto log = std::make_unique<Log>();
  log->path = path;
  log->fd = open(path.c_str(), O_RDWR | O_CLOEXEC);
  struct stat st {};
  if (log->fd < 0 || fstat(log->fd, &st) != 0) {
    const int err = errno;
    return IoError(path + ": cannot open the item log: " + ErrnoText(err));
  }
  const uint64_t size = static_cast<uint64_t>(st.st_size);

  uint8_t header[kFileHeaderBytes];
  if (size < kFileHeaderBytes) {
    return DataLossError(path + ": not an item log (" + std::to_string(size) +
                         " bytes, shorter than the file header); move it out of the store folder");
  }
  CAIRN_RETURN_IF_ERROR(ReadAt(path, log->fd, 0, header, sizeof header));
  const uint32_t magic = DecodeU32(header);
  const uint32_t version = DecodeU32(header + 4);
  if (magic != kFileMagic) {
    return DataLossError(path + ": not an item log (file magic " + Hex(magic) + ", expected " + Hex(kFileMagic) +
                         "); move it out of the store folder");
  }
  if (version != kFormatVersion) {
    return DataLossError(path + ": item log format version " + std::to_string(version) + ", this cairn reads " +
                         std::to_string(kFormatVersion));
  }
  CAIRN_RETURN_IF_ERROR(Scan(*log, size));
  logs_.emplace(id, std::move(log));
  return Status::Ok();
}

Status ItemStore::Scan(Log& log, uint64_t size) {
  uint64_t offset = kFileHeaderBytes;
  std::string reason;
  std::vector<uint8_t> rest;  // payload and CRC of one record
  while (offset < size) {
    const uint64_t left = size - offset;
    const uint64_t due = log.entries.size() + 1;
    if (left < kRecordHeaderBytes) {
      reason = "a record header cut short (" + std::to_string(left) + " of " + std::to_string(kRecordHeaderBytes) +
               " bytes)";
      break;
    }
    uint8_t bytes[kRecordHeaderBytes];
    CAIRN_RETURN_IF_ERROR(ReadAt(log.path, log.fd, offset, bytes, sizeof bytes));
    const RecordHeader h = DecodeHeader(bytes);
    if (h.magic != kRecordMagic) {
      reason = "no record magic (" + Hex(h.magic) + ")";
      break;
    }
    if (h.seq != due) {
      reason = "seq " + std::to_string(h.seq) + " where " + std::to_string(due) + " was due";
      break;
    }
    if (h.size > max_payload_) {
      reason = "a payload length of " + std::to_string(h.size) + " bytes, above the limit of " +
               std::to_string(max_payload_);
      break;
    }
    const uint64_t total = kRecordHeaderBytes + h.size + kCrcBytes;
    if (left < total) {
      reason = "the record of seq " + std::to_string(h.seq) + " cut short (" + std::to_string(left) + " of " +
               std::to_string(total) + " bytes)";
      break;
    }
    rest.resize(h.size + kCrcBytes);
    CAIRN_RETURN_IF_ERROR(ReadAt(log.path, log.fd, offset + kRecordHeaderBytes, rest.data(), rest.size()));
    Crc32 crc;
    crc.Update(bytes, sizeof bytes);
    crc.Update(rest.data(), h.size);
    if (crc.value() != DecodeU32(rest.data() + h.size)) {
      reason = "a CRC mismatch in the record of seq " + std::to_string(h.seq);
      break;
    }
    log.entries.push_back(Entry{offset, h.size, h.kind});
    offset += total;
  }
  log.end = offset;
  if (offset == size) return Status::Ok();
  // Cut where the log stops being whole; the items after it come again from the team.
  if (ftruncate(log.fd, static_cast<off_t>(offset)) != 0 || (options_.fsync && fsync(log.fd) != 0)) {
    const int err = errno;
    return IoError(log.path + ": cannot cut the damaged tail at byte " + std::to_string(offset) + " (" + reason +
                   "): " + ErrnoText(err));
  }
  recoveries_.push_back(ItemStoreRecovery{log.path, log.entries.size(), offset, size - offset, reason});
  return Status::Ok();
}

Expected<ItemStore::Log*> ItemStore::Create(const LogId& id) {
  // Written whole under a temporary name and renamed, so a log never exists without its header.
  auto log = std::make_unique<Log>();
  const std::string name = id.first + "." + std::to_string(id.second) + ".log";
  log->path = dir_ + "/" + name;
  const std::string tmp = dir_ + "/." + name + ".new";
  log->fd = open(tmp.c_str(), O_RDWR | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (log->fd < 0) {
    const int err = errno;
    return IoError(tmp + ": cannot create: " + ErrnoText(err));
  }
  ByteWriter header;
  header.U32(kFileMagic);
  header.U32(kFormatVersion);
  iovec iov{header.buffer().data(), header.size()};
  if (MoveAll(log->fd, 0, &iov, 1, true) != Transfer::kDone || (options_.fsync && fdatasync(log->fd) != 0) ||
      rename(tmp.c_str(), log->path.c_str()) != 0) {
    const int err = errno;
    unlink(tmp.c_str());
    return IoError(log->path + ": cannot create: " + ErrnoText(err));
  }
  if (options_.fsync) CAIRN_RETURN_IF_ERROR(SyncFolder(dir_));
  log->end = kFileHeaderBytes;
  return logs_.emplace(id, std::move(log)).first->second.get();
}

Status ItemStore::CutBack(Log& log) {
  if (ftruncate(log.fd, static_cast<off_t>(log.end)) != 0 || (options_.fsync && fsync(log.fd) != 0)) {
    const int err = errno;
    log.dirty = true;
    return IoError(log.path + ": cannot cut a failed append back to byte " + std::to_string(log.end) + ": " +
                   ErrnoText(err));
  }
  log.dirty = false;
  return Status::Ok();
}

Status ItemStore::Append(const StoreItem& item) {
  const ItemKey& k = item.key;
  const std::string what = "item " + KeyName(k);
  if (!ValidOrigin(k.origin))
    return InvalidArgumentError(what + ": the origin is not a robot name ([A-Za-z0-9_-]{1,32})");
  if (k.lane >= kMaxLanes)
    return InvalidArgumentError(what + ": lanes are 0.." + std::to_string(kMaxLanes - 1));
  if (k.seq == 0) return InvalidArgumentError(what + ": seqs start at 1");
  if (item.payload.size() > max_payload_) {
    return InvalidArgumentError(what + ": a payload of " + std::to_string(item.payload.size()) +
                                " bytes, above the limit of " + std::to_string(max_payload_));
  }
  const LogId id(k.origin, k.lane);
  const auto it = logs_.find(id);
  const uint64_t hwm = it == logs_.end() ? 0 : it->second->entries.size();
  if (k.seq <= hwm) {
    ++counters_.duplicates;
    return AlreadyExistsError(what + " is held already (high-water mark " + std::to_string(hwm) + ")");
  }
  if (k.seq != hwm + 1) {
    ++counters_.gaps;
    return FailedPreconditionError(what + " would leave a gap after the high-water mark " + std::to_string(hwm));
  }

  Log* log = nullptr;
  if (it != logs_.end()) {
    log = it->second.get();
  } else {
    auto created = Create(id);
    if (!created.ok()) {
      ++counters_.io_errors;
      return created.status().WithContext(what);
    }
    log = *created;
  }
  if (log->dirty) {
    if (Status s = CutBack(*log); !s.ok()) {
      ++counters_.io_errors;
      return s.WithContext(what);
    }
  }

  ByteWriter header;
  header.U32(kRecordMagic);
  header.U64(k.seq);
  header.U16(item.kind);
  header.U32(static_cast<uint32_t>(item.payload.size()));
  Crc32 crc;
  crc.Update(header.buffer().data(), header.size());
  crc.Update(item.payload.data(), item.payload.size());
  ByteWriter trailer;
  trailer.U32(crc.value());
  iovec iov[3] = {{header.buffer().data(), header.size()},
                  {const_cast<char*>(item.payload.data()), item.payload.size()},
                  {trailer.buffer().data(), trailer.size()}};
  if (MoveAll(log->fd, log->end, iov, 3, true) != Transfer::kDone || (options_.fsync && fdatasync(log->fd) != 0)) {
    const int err = errno;
    ++counters_.io_errors;
    std::string message = log->path + ": " + what + " at byte " + std::to_string(log->end) + ": " + ErrnoText(err);
    // Whatever part of the record reached the file goes, so the log stays whole and usable.
    if (Status cut = CutBack(*log); !cut.ok()) message += "; " + cut.message();
    return IoError(message);
  }
  log->entries.push_back(Entry{log->end, static_cast<uint32_t>(item.payload.size()), item.kind});
  log->end += header.size() + item.payload.size() + trailer.size();
  ++counters_.appended;
  return Status::Ok();
}

uint64_t ItemStore::HighWaterMark(const std::string& origin, uint8_t lane) const {
  const auto it = logs_.find(LogId(origin, lane));
  return it == logs_.end() ? 0 : it->second->entries.size();
}

std::map<std::pair<std::string, uint8_t>, uint64_t> ItemStore::HighWaterMarks() const {
  std::map<LogId, uint64_t> marks;
  for (const auto& [id, log] : logs_) {
    if (!log->entries.empty()) marks.emplace(id, log->entries.size());
  }
  return marks;
}

const ItemStore::Log* ItemStore::Find(const ItemKey& key) const {
  const auto it = logs_.find(LogId(key.origin, key.lane));
  if (it == logs_.end() || key.seq == 0 || key.seq > it->second->entries.size()) return nullptr;
  return it->second.get();
}

Expected<ItemInfo> ItemStore::Info(const ItemKey& key) const {
  const Log* log = Find(key);
  if (log == nullptr) return NotFoundError("item " + KeyName(key) + " is not held");
  const Entry& e = log->entries[key.seq - 1];
  return ItemInfo{e.kind, e.size};
}

Expected<StoreItem> ItemStore::Read(const ItemKey& key) const {
  const Log* log = Find(key);
  if (log == nullptr) return NotFoundError("item " + KeyName(key) + " is not held");
  const Entry& e = log->entries[key.seq - 1];
  const std::string where = log->path + ": item " + KeyName(key) + " at byte " + std::to_string(e.offset);
  StoreItem item;
  item.key = key;
  item.kind = e.kind;
  item.payload.resize(e.size);
  uint8_t bytes[kRecordHeaderBytes];
  uint8_t stored_crc[kCrcBytes];
  iovec iov[3] = {{bytes, sizeof bytes}, {item.payload.data(), item.payload.size()}, {stored_crc, sizeof stored_crc}};
  switch (MoveAll(log->fd, e.offset, iov, 3, false)) {
    case Transfer::kDone:
      break;
    case Transfer::kEnd:
      return DataLossError(where + ": the file ends inside it (cut since it was written)");
    case Transfer::kError: {
      const int err = errno;
      return IoError(where + ": " + ErrnoText(err));
    }
  }
  const RecordHeader h = DecodeHeader(bytes);
  Crc32 crc;
  crc.Update(bytes, sizeof bytes);
  crc.Update(item.payload.data(), item.payload.size());
  if (h.magic != kRecordMagic || h.seq != key.seq || h.kind != e.kind || h.size != e.size ||
      crc.value() != DecodeU32(stored_crc)) {
    return DataLossError(where + ": changed on disk since it was written (header or CRC)");
  }
  return item;
}

}  // namespace cairn
