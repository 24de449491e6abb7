#pragma once
// The rover profile's wheel CAN layout (`can:` in configs/rover.yaml), read without loading the whole
// daemon profile, for the test that holds the simulator's built-in layout to it.

#include <string>

#include "common/status.h"
#include "common/yaml_options_reader.h"
#include "drivers/can_wheel_options.h"
#include "tests/support/test_data.h"

namespace cairn::testing {

inline Expected<CanWheelOptions> LoadRoverProfileCanLayout() {
  const std::string path = SourceDir() + "/configs/rover.yaml";
  auto doc = LoadYamlWithOverrides(path, {});
  if (!doc.ok()) return doc.status();
  CanWheelOptions layout;
  YamlOptionsReader reader(doc->root["can"], path + " (can)", doc->overridden_keys);
  const Status st = reader.Read(layout);
  if (!st.ok()) return st;
  return layout;
}

}  // namespace cairn::testing
