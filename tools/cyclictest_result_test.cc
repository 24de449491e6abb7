#include "tools/cyclictest_result.h"

#include <gtest/gtest.h>

namespace cairn::tools {
namespace {

TEST(CyclictestReaderTest, QuantilesFromTheHistogram) {
  // 1000 wake-ups: 990 at 40 us, 8 at 300 us, 1 at 900 us, 1 at 1500 us.
  const char* text = R"({"thread": {"0": {"histogram": {"40": 990, "300": 8, "900": 1, "1500": 1},
                         "cycles": 1000, "min": 40, "max": 1500, "avg": 45.0}}})";
  const auto r = CyclictestReader::Parse(text, "ct.json");
  ASSERT_TRUE(r.ok()) << r.status().message();
  EXPECT_EQ(r->cycles, 1000u);
  EXPECT_EQ(r->median_us, 40.0);
  EXPECT_EQ(r->p999_us, 900.0);
  EXPECT_EQ(r->max_us, 1500.0);
  EXPECT_EQ(r->over_1ms, 1u);
}

TEST(CyclictestReaderTest, OverflowsCountAboveTheHistogram) {
  // -h 2000: two wake-ups beyond 2 ms are in "cycles" but in no bucket.
  const char* text = R"({"thread": {"0": {"histogram": {"30": 998}, "cycles": 1000, "max": 8287}}})";
  const auto r = CyclictestReader::Parse(text, "ct.json");
  ASSERT_TRUE(r.ok());
  EXPECT_EQ(r->over_1ms, 2u);
  EXPECT_EQ(r->p999_us, 8287.0);
  EXPECT_EQ(r->median_us, 30.0);
}

TEST(CyclictestReaderTest, ErrorsNameTheFileAndWhatIsMissing) {
  const auto no_thread = CyclictestReader::Parse(R"({"num_threads": 1})", "ct.json");
  ASSERT_FALSE(no_thread.ok());
  EXPECT_NE(no_thread.status().message().find("ct.json"), std::string::npos);
  const auto no_histogram = CyclictestReader::Parse(R"({"thread": {"0": {"cycles": 3, "max": 9}}})", "ct.json");
  ASSERT_FALSE(no_histogram.ok());
  EXPECT_NE(no_histogram.status().message().find("histogram"), std::string::npos);
  const auto bad_key = CyclictestReader::Parse(R"({"thread": {"0": {"histogram": {"x": 1}, "cycles": 1, "max": 9}}})", "ct.json");
  EXPECT_FALSE(bad_key.ok());
  EXPECT_FALSE(CyclictestReader::Parse("{\"thread\": ", "ct.json").ok());
  EXPECT_FALSE(CyclictestReader::Read("/nonexistent/ct.json").ok());
}

}  // namespace
}  // namespace cairn::tools
