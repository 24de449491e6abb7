#include "io/crc32.h"

#include <string>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(Crc32Test, StandardCheckValueAndIncrementalUpdates) {
  const std::string s = "123456789";
  EXPECT_EQ(Crc32::Of({reinterpret_cast<const uint8_t*>(s.data()), s.size()}), 0xCBF43926u);
  Crc32 c;
  c.Update(s.data(), 4);
  c.Update(s.data() + 4, 5);
  EXPECT_EQ(c.value(), 0xCBF43926u);
  EXPECT_EQ(Crc32::Of({}), 0u);
}

}  // namespace
}  // namespace cairn
