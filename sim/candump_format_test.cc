#include "sim/candump_format.h"

#include <gtest/gtest.h>

namespace cairn::sim {
namespace {

TEST(CandumpFormatTest, FormatsAndParsesStandardAndExtendedFrames) {
  can_frame f{};
  f.can_id = 0x101;
  f.len = 4;
  f.data[0] = 0xE8; f.data[1] = 0x03; f.data[2] = 0x00; f.data[3] = 0xFF;
  const std::string line = FormatCandumpLine(Timestamp::FromNanoseconds(1700000000123456789), "can0", f);
  EXPECT_EQ(line, "(1700000000.123457) can0 101#E80300FF");
  auto r = ParseCandumpLine(line);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->time.nanoseconds(), 1700000000123457000);
  EXPECT_EQ(r->interface, "can0");
  EXPECT_EQ(r->frame.can_id, 0x101u);
  EXPECT_EQ(r->frame.len, 4);
  EXPECT_EQ(r->frame.data[3], 0xFF);

  can_frame e{};
  e.can_id = 0x18FF0001u | CAN_EFF_FLAG;
  e.len = 0;
  const std::string ext = FormatCandumpLine(Timestamp::FromSeconds(2.0), "vcan1", e);
  EXPECT_EQ(ext, "(2.000000) vcan1 18FF0001#");
  auto re = ParseCandumpLine(ext);
  ASSERT_TRUE(re.ok());
  EXPECT_EQ(re->frame.can_id, 0x18FF0001u | CAN_EFF_FLAG);
  EXPECT_EQ(re->frame.len, 0);
}

TEST(CandumpFormatTest, RejectsMalformedLines) {
  for (const char* bad : {"", "1.000000 can0 101#00", "(1.0) can0 101#00", "(1.000000) can0 101",
                          "(1.000000) can0 1G1#00", "(1.000000) can0 101#0", "(1.000000) can0 101#001122334455667788",
                          // beyond int64 nanoseconds, or negative
                          "(176489282800.000000) can0 101#00", "(-1.000000) can0 101#00", "(1.-00001) can0 101#00"}) {
    EXPECT_FALSE(ParseCandumpLine(bad).ok()) << bad;
  }
}

}  // namespace
}  // namespace cairn::sim
