#include "common/status.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

Expected<int> ParsePositive(int v) {
  if (v <= 0) return InvalidArgumentError("value " + std::to_string(v) + " is not positive");
  return v;
}

Status Chain(int v) {
  CAIRN_RETURN_IF_ERROR(ParsePositive(v).status());
  return Status::Ok();
}

TEST(StatusTest, ExpectedHoldsValueOrError) {
  auto good = ParsePositive(3);
  ASSERT_TRUE(good.ok());
  EXPECT_EQ(*good, 3);
  auto bad = ParsePositive(-1);
  ASSERT_FALSE(bad.ok());
  EXPECT_EQ(bad.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(bad.status().ToString(), "invalid argument: value -1 is not positive");
}

TEST(StatusTest, ContextIsPrefixedAndCodeKept) {
  const Status s = Chain(0).WithContext("reading robot.yaml");
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(s.message(), "reading robot.yaml: value 0 is not positive");
  EXPECT_TRUE(Chain(2).ok());
}

}  // namespace
}  // namespace cairn
