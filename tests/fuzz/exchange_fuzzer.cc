// What a teammate, or anyone holding its key, can send: messages of the exchange protocol into a
// robot's exchange with a fresh store, then every item it stores through the item decoder. The
// input is a sequence of messages, each behind its length (2 bytes, little-endian).
#include <unistd.h>

#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <memory>
#include <string>
#include <string_view>

#include "daemon/comms/exchange.h"
#include "daemon/comms/item_store.h"
#include "daemon/comms/team_item_codec.h"
#include "tests/fuzz/team_names.h"

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  static const std::string dir = "/tmp/cairn_fuzz_exchange_" + std::to_string(getpid());
  // Gone when the fuzzer exits normally; a crash leaves the store of the input that caused it.
  static const bool removed_at_exit = std::atexit([] {
                                        std::error_code ec;
                                        std::filesystem::remove_all(dir, ec);
                                      }) == 0;
  (void)removed_at_exit;
  std::filesystem::remove_all(dir);
  cairn::ItemStoreOptions store_options;
  store_options.fsync = false;
  auto store = cairn::ItemStore::Open(dir, store_options);
  if (!store.ok()) return 0;
  const cairn::TeamItemCodec::Names names = cairn::fuzz::TeamNames();
  cairn::Exchange exchange("a", {"b", "c"}, **store, cairn::ExchangeOptions{},
                           [&](const cairn::StoreItem& item) { (void)cairn::TeamItemCodec::Decode(item, names); });
  exchange.ReplayStore();
  const auto send = [](const std::string&, std::string) { return true; };
  int64_t now_ns = 1000000000;
  for (size_t at = 0; at + 2 <= size;) {
    const size_t length = data[at] | (size_t{data[at + 1]} << 8);
    at += 2;
    const size_t n = std::min(length, size - at);
    exchange.OnMessage("b", std::string_view(reinterpret_cast<const char*>(data + at), n),
                       cairn::Timestamp::FromNanoseconds(now_ns));
    at += n;
    now_ns += 50000000;
    exchange.Pump(cairn::Timestamp::FromNanoseconds(now_ns), send);
  }
  (void)exchange.Settled(cairn::Timestamp::FromNanoseconds(now_ns));
  return 0;
}
