#include "daemon/comms/item_store.h"

#include <poll.h>
#include <signal.h>
#include <stdlib.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>
#include <random>
#include <string>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

namespace fs = std::filesystem;

constexpr uint64_t kFileHeader = 8;
constexpr uint64_t kRecordOverhead = 18 + 4;  // header and CRC around the payload

// Deterministic content, varied in size (some empty) and using every byte value.
std::string PayloadOf(const std::string& origin, uint8_t lane, uint64_t seq) {
  const size_t size = (seq * 131 + lane * 17 + origin.size() * 7) % 700;
  std::string p(size, '\0');
  for (size_t i = 0; i < size; ++i) p[i] = static_cast<char>((seq * 31 + i * 7 + lane + origin[0]) & 0xff);
  return p;
}

StoreItem ItemOf(const std::string& origin, uint8_t lane, uint64_t seq) {
  return StoreItem{ItemKey{origin, lane, seq}, static_cast<uint16_t>(seq % 5 + lane * 1000), PayloadOf(origin, lane, seq)};
}

// "" when the store holds exactly `expected`, else what differs.
std::string Mismatch(const ItemStore& store, const StoreItem& expected) {
  const std::string name = expected.key.origin + "/" + std::to_string(expected.key.lane) + "/" +
                           std::to_string(expected.key.seq);
  auto item = store.Read(expected.key);
  if (!item.ok()) return name + ": " + item.status().ToString();
  if (item->kind != expected.kind || item->payload != expected.payload) return name + ": other content";
  auto info = store.Info(expected.key);
  if (!info.ok() || info->kind != expected.kind || info->size != expected.payload.size()) return name + ": bad info";
  return "";
}

uint64_t LogBytes(const std::string& origin, uint8_t lane, uint64_t items) {
  uint64_t bytes = kFileHeader;
  for (uint64_t seq = 1; seq <= items; ++seq) bytes += kRecordOverhead + PayloadOf(origin, lane, seq).size();
  return bytes;
}

std::string ReadBytes(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), {});
}

void WriteBytes(const std::string& path, const std::string& bytes) {
  std::ofstream(path, std::ios::binary | std::ios::trunc) << bytes;
}

// Runs `body` in a forked child, where resource limits and crashes stay away from the test
// binary; returns the child's complaint ("" when all held).
std::string InChild(const std::function<std::string()>& body) {
  int fds[2];
  if (pipe(fds) != 0) return "pipe failed";
  const pid_t pid = fork();
  if (pid < 0) return "fork failed";
  if (pid == 0) {
    close(fds[0]);
    const std::string complaint = body();
    const ssize_t n = write(fds[1], complaint.data(), complaint.size());
    _exit(n == static_cast<ssize_t>(complaint.size()) ? 0 : 1);
  }
  close(fds[1]);
  std::string complaint;
  char buf[512];
  for (ssize_t n; (n = read(fds[0], buf, sizeof buf)) != 0;) {
    if (n < 0 && errno == EINTR) continue;
    if (n < 0) break;
    complaint.append(buf, static_cast<size_t>(n));
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) {
    complaint += " (child ended with status " + std::to_string(status) + ")";
  }
  return complaint;
}

class ItemStoreTest : public ::testing::Test {
 protected:
  void SetUp() override {
    char dir[] = "/tmp/cairn_item_store_XXXXXX";
    ASSERT_NE(mkdtemp(dir), nullptr);
    dir_ = dir;
  }
  void TearDown() override {
    std::error_code ec;
    fs::remove_all(dir_, ec);
  }

  std::unique_ptr<ItemStore> OpenStore(const ItemStoreOptions& options = {}) {
    auto store = ItemStore::Open(dir_, options);
    EXPECT_TRUE(store.ok()) << store.status().ToString();
    return store.ok() ? std::move(*store) : nullptr;
  }
  std::string LogPath(const std::string& origin, uint8_t lane) const {
    return dir_ + "/" + origin + "." + std::to_string(lane) + ".log";
  }
  void AppendAll(ItemStore& store, const std::string& origin, uint8_t lane, uint64_t from, uint64_t to) {
    for (uint64_t seq = from; seq <= to; ++seq) {
      const Status s = store.Append(ItemOf(origin, lane, seq));
      ASSERT_TRUE(s.ok()) << s.ToString();
    }
  }

  std::string dir_;
};

TEST_F(ItemStoreTest, RoundTripOverOriginsAndLanesSurvivesReopen) {
  const std::map<std::pair<std::string, uint8_t>, uint64_t> expected = {
      {{"alpha", 0}, 7}, {{"alpha", 3}, 2}, {{"bravo-2", 0}, 5}, {{"bravo-2", 1}, 1}, {{"C_3", 1}, 4}};
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  EXPECT_TRUE(store->HighWaterMarks().empty());
  for (uint64_t seq = 1; seq <= 7; ++seq) {  // interleaved, as items arrive from a team
    for (const auto& [id, count] : expected) {
      if (seq <= count) {
        ASSERT_TRUE(store->Append(ItemOf(id.first, id.second, seq)).ok());
      }
    }
  }
  EXPECT_EQ(store->counters().appended, 19u);
  EXPECT_EQ(store->HighWaterMarks(), expected);
  EXPECT_EQ(store->HighWaterMark("alpha", 0), 7u);
  EXPECT_EQ(store->HighWaterMark("alpha", 1), 0u);
  EXPECT_EQ(store->HighWaterMark("delta", 0), 0u);
  for (const auto& [id, count] : expected) {
    for (uint64_t seq = 1; seq <= count; ++seq) EXPECT_EQ(Mismatch(*store, ItemOf(id.first, id.second, seq)), "");
  }
  EXPECT_EQ(store->Read(ItemKey{"alpha", 0, 8}).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store->Read(ItemKey{"alpha", 0, 0}).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store->Read(ItemKey{"alpha", 2, 1}).status().code(), StatusCode::kNotFound);
  EXPECT_EQ(store->Info(ItemKey{"zulu", 0, 1}).status().code(), StatusCode::kNotFound);

  store.reset();
  store = OpenStore();
  ASSERT_NE(store, nullptr);
  EXPECT_TRUE(store->recoveries().empty());
  EXPECT_EQ(store->HighWaterMarks(), expected);
  for (const auto& [id, count] : expected) {
    for (uint64_t seq = 1; seq <= count; ++seq) EXPECT_EQ(Mismatch(*store, ItemOf(id.first, id.second, seq)), "");
    EXPECT_EQ(fs::file_size(LogPath(id.first, id.second)), LogBytes(id.first, id.second, count));
  }
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), {}), static_cast<long>(expected.size()))
      << "one file per log, no temporaries left";
  ASSERT_TRUE(store->Append(ItemOf("alpha", 3, 3)).ok());
  EXPECT_EQ(Mismatch(*store, ItemOf("alpha", 3, 3)), "");
}

TEST_F(ItemStoreTest, DuplicatesAndGapsAreRefusedAndCounted) {
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  AppendAll(*store, "a", 0, 1, 3);
  const uint64_t size = fs::file_size(LogPath("a", 0));

  StoreItem again = ItemOf("a", 0, 2);
  again.payload = "another payload";
  Status s = store->Append(again);
  EXPECT_EQ(s.code(), StatusCode::kAlreadyExists) << s.ToString();
  EXPECT_NE(s.message().find("a/0/2"), std::string::npos) << s.message();
  EXPECT_EQ(store->Append(ItemOf("a", 0, 3)).code(), StatusCode::kAlreadyExists);
  s = store->Append(ItemOf("a", 0, 5));
  EXPECT_EQ(s.code(), StatusCode::kFailedPrecondition) << s.ToString();
  EXPECT_NE(s.message().find("a/0/5"), std::string::npos) << s.message();
  EXPECT_EQ(store->Append(ItemOf("b", 1, 2)).code(), StatusCode::kFailedPrecondition);

  EXPECT_EQ(store->counters().appended, 3u);
  EXPECT_EQ(store->counters().duplicates, 2u);
  EXPECT_EQ(store->counters().gaps, 2u);
  EXPECT_EQ(store->counters().io_errors, 0u);
  EXPECT_EQ(store->HighWaterMark("a", 0), 3u);
  EXPECT_EQ(store->HighWaterMark("b", 1), 0u);
  EXPECT_EQ(fs::file_size(LogPath("a", 0)), size);
  EXPECT_FALSE(fs::exists(LogPath("b", 1)));
  EXPECT_EQ(Mismatch(*store, ItemOf("a", 0, 2)), "");

  store.reset();
  store = OpenStore();
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(store->HighWaterMarks(), (std::map<std::pair<std::string, uint8_t>, uint64_t>{{{"a", 0}, 3}}));
  ASSERT_TRUE(store->Append(ItemOf("a", 0, 4)).ok());
}

TEST_F(ItemStoreTest, TornTailIsCutAndTheLostItemAppendsAgain) {
  constexpr uint64_t kItems = 6;
  {
    auto store = OpenStore();
    ASSERT_NE(store, nullptr);
    AppendAll(*store, "rover", 1, 1, kItems);
  }
  const std::string path = LogPath("rover", 1);
  const std::string whole = ReadBytes(path);
  const uint64_t last = LogBytes("rover", 1, kItems - 1);  // where the last record starts
  const uint64_t payload = PayloadOf("rover", 1, kItems).size();
  ASSERT_GT(payload, 10u);
  ASSERT_EQ(whole.size(), last + kRecordOverhead + payload);

  const uint64_t cuts[] = {last,      last + 1,           last + 10,          last + 18,
                           last + 19, last + 18 + payload / 2, last + 18 + payload, last + 18 + payload + 3};
  for (const uint64_t cut : cuts) {
    SCOPED_TRACE("cut at byte " + std::to_string(cut));
    WriteBytes(path, whole);
    fs::resize_file(path, cut);
    auto store = OpenStore();
    ASSERT_NE(store, nullptr);
    EXPECT_EQ(store->HighWaterMark("rover", 1), kItems - 1);
    if (cut == last) {
      EXPECT_TRUE(store->recoveries().empty()) << "a whole record cut off is no damage";
    } else {
      ASSERT_EQ(store->recoveries().size(), 1u);
      const ItemStoreRecovery& r = store->recoveries()[0];
      EXPECT_EQ(r.file, path);
      EXPECT_EQ(r.offset, last);
      EXPECT_EQ(r.valid_items, kItems - 1);
      EXPECT_EQ(r.dropped_bytes, cut - last);
      EXPECT_FALSE(r.reason.empty());
    }
    EXPECT_EQ(fs::file_size(path), last);
    for (uint64_t seq = 1; seq < kItems; ++seq) EXPECT_EQ(Mismatch(*store, ItemOf("rover", 1, seq)), "");
    ASSERT_TRUE(store->Append(ItemOf("rover", 1, kItems)).ok());
    store.reset();
    store = OpenStore();
    ASSERT_NE(store, nullptr);
    EXPECT_TRUE(store->recoveries().empty());
    EXPECT_EQ(store->HighWaterMark("rover", 1), kItems);
    EXPECT_EQ(Mismatch(*store, ItemOf("rover", 1, kItems)), "");
  }
}

TEST_F(ItemStoreTest, CorruptMiddleRecordKeepsTheItemsBeforeIt) {
  constexpr uint64_t kItems = 5;
  {
    auto store = OpenStore();
    ASSERT_NE(store, nullptr);
    AppendAll(*store, "hexa", 0, 1, kItems);
  }
  const std::string path = LogPath("hexa", 0);
  const std::string whole = ReadBytes(path);
  const uint64_t third = LogBytes("hexa", 0, 2);
  const uint64_t payload = PayloadOf("hexa", 0, 3).size();
  ASSERT_GT(payload, 10u);
  // Magic, seq, kind, length, payload, CRC.
  const uint64_t flips[] = {0, 5, 12, 16, 18 + payload / 2, 18 + payload + 1};
  for (const uint64_t flip : flips) {
    SCOPED_TRACE("byte " + std::to_string(flip) + " of the third record flipped");
    std::string bytes = whole;
    bytes[third + flip] = static_cast<char>(bytes[third + flip] ^ 0x5a);
    WriteBytes(path, bytes);
    auto store = OpenStore();
    ASSERT_NE(store, nullptr);
    EXPECT_EQ(store->HighWaterMark("hexa", 0), 2u);
    ASSERT_EQ(store->recoveries().size(), 1u);
    const ItemStoreRecovery& r = store->recoveries()[0];
    EXPECT_EQ(r.file, path);
    EXPECT_EQ(r.offset, third);
    EXPECT_EQ(r.valid_items, 2u);
    EXPECT_EQ(r.dropped_bytes, whole.size() - third);
    if (flip == 18 + payload / 2) {
      EXPECT_NE(r.reason.find("CRC"), std::string::npos) << r.reason;
    }
    EXPECT_EQ(Mismatch(*store, ItemOf("hexa", 0, 1)), "");
    EXPECT_EQ(Mismatch(*store, ItemOf("hexa", 0, 2)), "");
    EXPECT_EQ(store->Read(ItemKey{"hexa", 0, 3}).status().code(), StatusCode::kNotFound);
    EXPECT_EQ(fs::file_size(path), third);
    EXPECT_TRUE(store->Append(ItemOf("hexa", 0, 3)).ok());
  }

  // A whole, valid record written twice is no item 6: the log must count on.
  const uint64_t second = LogBytes("hexa", 0, 1);
  WriteBytes(path, whole + whole.substr(second, third - second));
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  EXPECT_EQ(store->HighWaterMark("hexa", 0), kItems);
  ASSERT_EQ(store->recoveries().size(), 1u);
  EXPECT_EQ(store->recoveries()[0].offset, whole.size());
  EXPECT_NE(store->recoveries()[0].reason.find("seq 2 where 6"), std::string::npos) << store->recoveries()[0].reason;
  EXPECT_EQ(fs::file_size(path), whole.size());
}

TEST_F(ItemStoreTest, ReadNoticesTheDiskChangingUnderTheStore) {
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  AppendAll(*store, "a", 2, 1, 3);
  const std::string path = LogPath("a", 2);
  const uint64_t second = LogBytes("a", 2, 1);
  std::string bytes = ReadBytes(path);
  bytes[second + 20] = static_cast<char>(bytes[second + 20] ^ 1);
  WriteBytes(path, bytes);
  const auto read = store->Read(ItemKey{"a", 2, 2});
  EXPECT_EQ(read.status().code(), StatusCode::kDataLoss);
  EXPECT_NE(read.status().message().find(path), std::string::npos) << read.status().message();
  EXPECT_NE(read.status().message().find("byte " + std::to_string(second)), std::string::npos)
      << read.status().message();
  EXPECT_EQ(Mismatch(*store, ItemOf("a", 2, 1)), "");
  EXPECT_EQ(Mismatch(*store, ItemOf("a", 2, 3)), "");
  fs::resize_file(path, fs::file_size(path) - 1);
  EXPECT_EQ(store->Read(ItemKey{"a", 2, 3}).status().code(), StatusCode::kDataLoss);
}

TEST_F(ItemStoreTest, ForeignFileStopsTheOpenAndIsLeftAlone) {
  const std::string path = LogPath("alpha", 0);
  const std::string text = "not an item log, whatever its name says\n";
  WriteBytes(path, text);
  auto store = ItemStore::Open(dir_, {});
  ASSERT_FALSE(store.ok());
  EXPECT_NE(store.status().message().find(path), std::string::npos) << store.status().message();
  EXPECT_EQ(ReadBytes(path), text);

  WriteBytes(path, "abc");  // shorter than a file header
  store = ItemStore::Open(dir_, {});
  ASSERT_FALSE(store.ok());
  EXPECT_NE(store.status().message().find(path), std::string::npos) << store.status().message();

  // A log of a later format version: the right magic, not ours to repair.
  {
    fs::remove(path);
    auto writer = OpenStore();
    ASSERT_NE(writer, nullptr);
    AppendAll(*writer, "alpha", 0, 1, 2);
  }
  std::string bytes = ReadBytes(path);
  bytes[4] = 2;
  WriteBytes(path, bytes);
  store = ItemStore::Open(dir_, {});
  ASSERT_FALSE(store.ok());
  EXPECT_NE(store.status().message().find(path), std::string::npos) << store.status().message();
  EXPECT_NE(store.status().message().find("version 2"), std::string::npos) << store.status().message();
  EXPECT_EQ(ReadBytes(path), bytes);
}

TEST_F(ItemStoreTest, FilesNotNamedLikeLogsAreIgnored) {
  const std::vector<std::string> others = {"notes.txt", "alpha.4.log", "alpha.0.log.bak", "al.pha.0.log",
                                           "alpha.0.txt", "alpha.00.log", ".log"};
  for (const std::string& name : others) WriteBytes(dir_ + "/" + name, "junk");
  fs::create_directory(dir_ + "/beta.0.log");
  auto store = OpenStore();
  ASSERT_NE(store, nullptr);
  EXPECT_TRUE(store->HighWaterMarks().empty());
  EXPECT_TRUE(store->recoveries().empty());
  ASSERT_TRUE(store->Append(ItemOf("alpha", 0, 1)).ok());
  for (const std::string& name : others) EXPECT_EQ(ReadBytes(dir_ + "/" + name), "junk") << name;
}

TEST_F(ItemStoreTest, DiskFullIsAnIoErrorAndLeavesWholeRecords) {
  const std::string dir = dir_;
  const std::string complaint = InChild([&dir]() -> std::string {
    signal(SIGXFSZ, SIG_IGN);
    rlimit limit{};
    getrlimit(RLIMIT_FSIZE, &limit);
    limit.rlim_cur = 8192;
    if (setrlimit(RLIMIT_FSIZE, &limit) != 0) return "setrlimit failed";
    auto item = [](uint64_t seq, size_t size) {
      return StoreItem{ItemKey{"full", 0, seq}, 7, std::string(size, static_cast<char>('a' + seq % 26))};
    };
    std::vector<StoreItem> held;
    Status failed;
    {
      auto opened = ItemStore::Open(dir, {});
      if (!opened.ok()) return "open: " + opened.status().ToString();
      ItemStore& store = **opened;
      for (uint64_t seq = 1; seq <= 100 && failed.ok(); ++seq) {
        failed = store.Append(item(seq, 900));
        if (failed.ok()) held.push_back(item(seq, 900));
      }
      if (failed.ok()) return "100 items of 900 bytes fitted in 8 KB";
      if (failed.code() != StatusCode::kIoError) return "not an I/O error: " + failed.ToString();
      if (failed.message().find("full.0.log") == std::string::npos) return "unnamed file: " + failed.message();
      if (held.empty()) return "not even one item fitted";
      if (store.counters().io_errors != 1) return "io_errors " + std::to_string(store.counters().io_errors);
      if (store.HighWaterMark("full", 0) != held.size()) return "mark moved on a failed append";
      const uint64_t size = fs::file_size(dir + "/full.0.log");
      if (size != kFileHeader + held.size() * (kRecordOverhead + 900))
        return "a partial record was left: " + std::to_string(size) + " bytes";
      // Still usable: a smaller item fits in what is left, a large one fails the same way.
      const StoreItem small = item(held.size() + 1, 100);
      if (Status s = store.Append(small); !s.ok()) return "small item after the failure: " + s.ToString();
      held.push_back(small);
      if (store.Append(item(held.size() + 1, 900)).code() != StatusCode::kIoError) return "second failure";
    }
    auto reopened = ItemStore::Open(dir, {});
    if (!reopened.ok()) return "reopen: " + reopened.status().ToString();
    if (!(*reopened)->recoveries().empty()) return "recovery needed: " + (*reopened)->recoveries()[0].reason;
    if ((*reopened)->HighWaterMark("full", 0) != held.size()) return "mark after reopen";
    for (const StoreItem& h : held) {
      if (std::string m = Mismatch(**reopened, h); !m.empty()) return m;
    }
    return "";
  });
  EXPECT_EQ(complaint, "");
}

TEST_F(ItemStoreTest, SigkillLosesNoAcknowledgedItem) {
  const std::string origin = "killed";
  std::mt19937 rng(std::random_device{}());
  const uint32_t seed = rng();
  SCOPED_TRACE("delay seed " + std::to_string(seed));
  std::uniform_int_distribution<int> delay_ms(5, 80);
  rng.seed(seed);
  uint64_t hwm = 0;
  int torn = 0;
  for (int round = 0; round < 5; ++round) {
    SCOPED_TRACE("round " + std::to_string(round) + ", starting at " + std::to_string(hwm));
    int fds[2];
    ASSERT_EQ(pipe(fds), 0);
    const pid_t pid = fork();
    ASSERT_GE(pid, 0);
    if (pid == 0) {
      close(fds[0]);
      auto store = ItemStore::Open(dir_, {});
      if (!store.ok()) _exit(3);
      for (uint64_t seq = (*store)->HighWaterMark(origin, 0) + 1;; ++seq) {
        if (!(*store)->Append(ItemOf(origin, 0, seq)).ok()) _exit(4);
        if (write(fds[1], &seq, sizeof seq) != sizeof seq) _exit(5);
      }
    }
    close(fds[1]);
    std::string reported;
    auto drain = [&](int timeout_ms) {
      pollfd p{fds[0], POLLIN, 0};
      if (poll(&p, 1, timeout_ms) <= 0) return false;
      char buf[4096];
      const ssize_t n = read(fds[0], buf, sizeof buf);
      if (n > 0) reported.append(buf, static_cast<size_t>(n));
      return n > 0;
    };
    while (reported.size() < sizeof(uint64_t) && drain(5000)) {
    }
    const auto kill_at = std::chrono::steady_clock::now() + std::chrono::milliseconds(delay_ms(rng));
    while (std::chrono::steady_clock::now() < kill_at) {
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(kill_at - std::chrono::steady_clock::now());
      drain(static_cast<int>(left.count()) + 1);
    }
    kill(pid, SIGKILL);
    int status = 0;
    waitpid(pid, &status, 0);
    while (drain(1000)) {
    }
    close(fds[0]);
    ASSERT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == SIGKILL) << "child status " << status;
    ASSERT_GT(reported.size(), 0u) << "the child appended nothing";
    ASSERT_EQ(reported.size() % sizeof(uint64_t), 0u);

    std::vector<uint64_t> seqs(reported.size() / sizeof(uint64_t));
    std::memcpy(seqs.data(), reported.data(), reported.size());
    for (size_t i = 0; i < seqs.size(); ++i) ASSERT_EQ(seqs[i], hwm + 1 + i) << "reported out of order";

    auto store = OpenStore();
    ASSERT_NE(store, nullptr);
    const uint64_t now = store->HighWaterMark(origin, 0);
    // Every acknowledged item is held; at most the one being acknowledged when killed is extra.
    EXPECT_GE(now, seqs.back());
    EXPECT_LE(now, seqs.back() + 1);
    for (const ItemStoreRecovery& r : store->recoveries()) {
      ++torn;
      EXPECT_EQ(r.valid_items, now) << r.reason;
    }
    for (uint64_t seq = 1; seq <= now; ++seq) ASSERT_EQ(Mismatch(*store, ItemOf(origin, 0, seq)), "");
    EXPECT_EQ(fs::file_size(LogPath(origin, 0)), LogBytes(origin, 0, now)) << "exactly the records 1.." << now;
    hwm = now;
  }
  EXPECT_GT(hwm, 5u);
  std::printf("  %llu items over 5 kills, %d torn records cut\n", static_cast<unsigned long long>(hwm), torn);
}

TEST_F(ItemStoreTest, OversizedPayloadsAndBadNamesAreRefused) {
  ItemStoreOptions options;
  options.max_item_bytes = 1000;
  auto store = OpenStore(options);
  ASSERT_NE(store, nullptr);
  Status s = store->Append(StoreItem{ItemKey{"a", 0, 1}, 1, std::string(1001, 'x')});
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << s.ToString();
  EXPECT_NE(s.message().find("a/0/1"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("1001"), std::string::npos) << s.message();
  EXPECT_TRUE(store->Append(StoreItem{ItemKey{"a", 0, 1}, 1, std::string(1000, 'x')}).ok());

  const std::string bad[] = {"", std::string(33, 'r'), "a.b", "a/b", "../a", "a b", "ro\xc3\xbc" "bot", "tab\t"};
  for (const std::string& origin : bad) {
    EXPECT_FALSE(ItemStore::ValidOrigin(origin)) << origin;
    EXPECT_EQ(store->Append(StoreItem{ItemKey{origin, 0, 1}, 1, "p"}).code(), StatusCode::kInvalidArgument) << origin;
  }
  EXPECT_EQ(store->Append(StoreItem{ItemKey{"a", 4, 1}, 1, "p"}).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->Append(StoreItem{ItemKey{"a", 255, 1}, 1, "p"}).code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(store->Append(StoreItem{ItemKey{"b", 0, 0}, 1, "p"}).code(), StatusCode::kInvalidArgument);
  EXPECT_TRUE(store->Append(StoreItem{ItemKey{std::string(32, 'r'), 0, 1}, 1, "p"}).ok());
  EXPECT_TRUE(store->Append(StoreItem{ItemKey{"Robot_1-x", 3, 1}, 1, ""}).ok());

  EXPECT_EQ(store->counters().appended, 3u);
  EXPECT_EQ(store->counters().duplicates + store->counters().gaps + store->counters().io_errors, 0u);
  EXPECT_EQ(std::distance(fs::directory_iterator(dir_), {}), 3) << "no file for a refused item";
}

}  // namespace
}  // namespace cairn
