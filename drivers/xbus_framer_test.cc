#include "drivers/xbus_framer.h"

#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

struct Received {
  uint8_t mid;
  std::vector<uint8_t> payload;
};

std::vector<Received> FeedAll(XbusFramer& f, const std::vector<uint8_t>& bytes, size_t chunk) {
  std::vector<Received> out;
  for (size_t i = 0; i < bytes.size(); i += chunk) {
    const size_t n = std::min(chunk, bytes.size() - i);
    f.Feed(std::span<const uint8_t>(bytes.data() + i, n),
           [&](const XbusMessage& m) { out.push_back({m.mid, {m.payload.begin(), m.payload.end()}}); });
  }
  return out;
}

TEST(XbusFramerTest, EncodesTheChecksumAndReadsBackInAnyChunking) {
  // GoToConfig as the manual spells it: FA FF 30 00 D1.
  EXPECT_EQ(XbusFramer::Encode(0x30, {}), (std::vector<uint8_t>{0xFA, 0xFF, 0x30, 0x00, 0xD1}));
  std::vector<uint8_t> big(300);
  for (size_t i = 0; i < big.size(); ++i) big[i] = static_cast<uint8_t>(i * 7);
  std::vector<uint8_t> stream = XbusFramer::Encode(0x36, std::vector<uint8_t>{1, 2, 0xFA, 4});
  const std::vector<uint8_t> extended = XbusFramer::Encode(0x36, big);
  EXPECT_EQ(extended[3], 0xFF);  // extended length
  stream.insert(stream.end(), extended.begin(), extended.end());
  for (const size_t chunk : {size_t{1}, size_t{3}, size_t{64}, stream.size()}) {
    XbusFramer f;
    const std::vector<Received> got = FeedAll(f, stream, chunk);
    ASSERT_EQ(got.size(), 2u) << chunk;
    EXPECT_EQ(got[0].payload, (std::vector<uint8_t>{1, 2, 0xFA, 4}));
    EXPECT_EQ(got[1].payload, big);
    EXPECT_EQ(f.counts().checksum_errors + f.counts().skipped_bytes, 0u);
    EXPECT_EQ(f.pending(), 0u);
  }
}

TEST(XbusFramerTest, ResynchronizesAfterGarbageAndDamagedMessages) {
  const std::vector<uint8_t> good = XbusFramer::Encode(0x36, std::vector<uint8_t>{9, 8, 7});
  std::vector<uint8_t> stream = {0x00, 0xFA, 0x13};  // noise with a false preamble
  stream.insert(stream.end(), good.begin(), good.end());
  std::vector<uint8_t> damaged = good;
  damaged[5] ^= 0x40;  // a flipped bit in the payload
  stream.insert(stream.end(), damaged.begin(), damaged.end());
  std::vector<uint8_t> cut = good;
  cut.resize(4);  // the line dropped the rest
  stream.insert(stream.end(), cut.begin(), cut.end());
  stream.insert(stream.end(), good.begin(), good.end());
  stream.insert(stream.end(), {0xFA, 0xFF, 0x36, 0xFF, 0x7F, 0xFF});  // declares 32 KB
  stream.insert(stream.end(), good.begin(), good.end());
  XbusFramer f;
  const std::vector<Received> got = FeedAll(f, stream, 5);
  ASSERT_EQ(got.size(), 3u);
  for (const Received& r : got) EXPECT_EQ(r.payload, (std::vector<uint8_t>{9, 8, 7}));
  EXPECT_GE(f.counts().checksum_errors, 2u);
  EXPECT_GE(f.counts().length_errors, 1u);  // the 32 KB one, and the false preamble read as a long one
  EXPECT_GT(f.counts().skipped_bytes, 0u);
}

}  // namespace
}  // namespace cairn
