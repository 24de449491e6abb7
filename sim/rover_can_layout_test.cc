#include "sim/rover_can_layout.h"

#include <gtest/gtest.h>

#include "common/options_yaml_writer.h"
#include "sim/testing/rover_profile_can_layout.h"

namespace cairn::sim {
namespace {

// The built-in layout is the rover profile's: `cairn sim` and cairnd encode and decode alike.
TEST(RoverCanLayoutTest, EqualsTheRoverProfile) {
  auto profile = testing::LoadRoverProfileCanLayout();
  ASSERT_TRUE(profile.ok()) << profile.status().ToString();
  CanWheelOptions built_in = RoverCanLayout();
  EXPECT_EQ(OptionsYamlWriter::Write(built_in), OptionsYamlWriter::Write(*profile));
  EXPECT_TRUE(built_in.Validate().ok());
}

}  // namespace
}  // namespace cairn::sim
