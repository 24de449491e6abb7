#pragma once
// World files for `cairn sim --world`: read through the options visitor, so every missing,
// unknown or out-of-range key is reported with file, line and key.

#include <string>

#include "common/status.h"
#include "sim/world_options.h"

namespace cairn::sim {

Expected<WorldOptions> LoadWorldFile(const std::string& path);
// The effective world as YAML (each key with unit and range), as written next to a mission.
std::string WorldFileText(const WorldOptions& world);

}  // namespace cairn::sim
