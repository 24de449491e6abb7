#pragma once
// World files for `cairn sim --world`: read through the options visitor, so every missing,
// unknown or out-of-range key is reported with file, line and key.

#include <string>

#include "drivers/simulator/world_options.h"
#include "hal/status.h"

namespace cairn::sim {

Expected<WorldOptions> LoadWorldFile(const std::string& path);
// The effective world as YAML (each key with unit and range), as written next to a mission.
std::string WorldFileText(const WorldOptions& world);

}  // namespace cairn::sim
