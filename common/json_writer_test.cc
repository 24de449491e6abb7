#include "common/json_writer.h"

#include <cmath>
#include <limits>

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(JsonWriterTest, CompactNestedDocument) {
  JsonWriter j(false);
  j.BeginObject();
  j.Field("a", 1).Field("b", "x\"y\n");
  j.Key("c").BeginArray().Int(-2).Number(0.5).Bool(true).Null().EndArray();
  j.Key("d").BeginObject().EndObject();
  j.EndObject();
  EXPECT_EQ(j.str(), R"({"a":1,"b":"x\"y\n","c":[-2,0.5,true,null],"d":{}})");
}

TEST(JsonWriterTest, NumbersAreShortestExactAndNonFiniteIsNull) {
  JsonWriter j(false);
  j.BeginArray().Number(200.0).Number(0.1).Number(1.0 / 3.0).Number(std::nan(""));
  j.Number(std::numeric_limits<double>::infinity()).Number(1e300).EndArray();
  EXPECT_EQ(j.str(), "[200,0.1,0.3333333333333333,null,null,1e+300]");
}

TEST(JsonWriterTest, ControlCharactersAreEscaped) {
  EXPECT_EQ(JsonWriter::Escape(std::string("a\x01z\t", 4)), "a\\u0001z\\t");
}

}  // namespace
}  // namespace cairn
