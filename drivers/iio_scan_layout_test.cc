#include "drivers/iio_scan_layout.h"

#include <vector>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(IioScanLayoutTest, ParsesChannelTypesAndRefusesOthersWithTheText) {
  const auto t = IioChannelType::Parse("be:s14/16>>2\n");
  ASSERT_TRUE(t.ok()) << t.status().ToString();
  EXPECT_TRUE(t->big_endian);
  EXPECT_TRUE(t->is_signed);
  EXPECT_EQ(t->bits, 14);
  EXPECT_EQ(t->storage_bits, 16);
  EXPECT_EQ(t->shift, 2);
  const auto u = IioChannelType::Parse("le:u12/16>>0");
  ASSERT_TRUE(u.ok());
  EXPECT_FALSE(u->big_endian || u->is_signed);
  for (const char* bad : {"", "xe:s16/16>>0", "le:s16/12>>0", "le:s16/24>>0", "le:s16/16>>4", "le:s16/16>>0X2"}) {
    const auto r = IioChannelType::Parse(bad);
    EXPECT_FALSE(r.ok()) << bad;
    EXPECT_NE(r.status().message().find(bad), std::string::npos) << r.status().message();
  }
}

TEST(IioScanLayoutTest, PlacesChannelsAtTheirAlignmentAndExtractsValues) {
  // Three 16-bit channels and a 64-bit timestamp: 6 bytes, padding to 8, the timestamp, 16 in all.
  std::vector<IioChannel> channels = {{"in_timestamp", 9, *IioChannelType::Parse("le:s64/64>>0"), 0},
                                      {"in_accel_z", 3, *IioChannelType::Parse("be:s14/16>>0"), 0},
                                      {"in_accel_x", 1, *IioChannelType::Parse("be:s14/16>>0"), 0},
                                      {"in_temp", 5, *IioChannelType::Parse("le:u12/16>>4"), 0}};
  const auto layout = IioScanLayout::Create(channels);
  ASSERT_TRUE(layout.ok()) << layout.status().ToString();
  EXPECT_EQ(layout->record_size(), 16u);
  EXPECT_EQ(layout->channels()[0].name, "in_accel_x");
  EXPECT_EQ(layout->channels()[3].offset, 8u);
  const std::vector<uint8_t> record = {0x3F, 0xFF,  // -1 in 14 bits
                                       0x1F, 0xFF,  // 8191
                                       0x50, 0x12,  // 0x1250 >> 4 = 0x125
                                       0,    0,     // padding
                                       0x01, 0x02, 0x03, 0x04, 0x05, 0x06, 0x07, 0x08};
  EXPECT_EQ(layout->Value(record, 0), -1);
  EXPECT_EQ(layout->Value(record, 1), 8191);
  EXPECT_EQ(layout->Value(record, 2), 0x125);
  EXPECT_EQ(layout->Value(record, 3), 0x0807060504030201);
  EXPECT_EQ(layout->Find("in_temp"), 2);
  EXPECT_EQ(layout->Find("in_anglvel_x"), -1);
  channels[1].index = 1;  // two channels at index 1
  EXPECT_FALSE(IioScanLayout::Create(channels).ok());
}

}  // namespace
}  // namespace cairn
