#include "io/compression.h"

#include <cstdint>
#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(CompressorTest, EveryCodecRoundTrips) {
  std::vector<uint8_t> data(100000);
  for (size_t i = 0; i < data.size(); ++i) data[i] = static_cast<uint8_t>((i * 7) % 13);
  for (Compression c : {Compression::kNone, Compression::kZstd, Compression::kLz4}) {
    std::vector<uint8_t> packed, back;
    ASSERT_TRUE(Compressor::Compress(c, data, &packed).ok());
    ASSERT_TRUE(Compressor::Decompress(c, packed, data.size(), &back).ok());
    EXPECT_EQ(back, data);
  }
}

TEST(CompressorTest, AnEmptyBlockDecompressesToNothing) {
  std::vector<uint8_t> back(3, 1);
  EXPECT_TRUE(Compressor::Decompress(Compression::kNone, {}, 0, &back).ok());
  EXPECT_TRUE(back.empty());
}

// A block from a file or a teammate that claims more bytes than it can hold is refused before
// anything that size is allocated.
TEST(CompressorTest, ASizeTheBlockCannotHoldIsRefusedUnallocated) {
  const std::vector<uint8_t> data(1000, 7);
  for (Compression c : {Compression::kNone, Compression::kZstd, Compression::kLz4}) {
    std::vector<uint8_t> packed, back;
    ASSERT_TRUE(Compressor::Compress(c, data, &packed).ok());
    for (uint64_t claimed : {uint64_t{1000000}, uint64_t{1} << 31, ~uint64_t{0}}) {
      const Status s = Compressor::Decompress(c, packed, claimed, &back);
      EXPECT_FALSE(s.ok()) << Compressor::Name(c) << " " << claimed;
      EXPECT_LT(back.capacity(), size_t{1} << 20) << Compressor::Name(c) << " " << claimed;
    }
    EXPECT_FALSE(Compressor::Decompress(c, packed, 999, &back).ok()) << Compressor::Name(c);
  }
}

}  // namespace
}  // namespace cairn
