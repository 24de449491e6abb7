#pragma once

#include <string>

namespace cairn::testing {

// Installs tests/js/package.json (third-party JavaScript clients: Foxglove's MCAP reader and
// WebSocket client, protobufjs) into the build tree once, and copies the check scripts next to
// it. Returns the folder, or "" with the reason when node, npm or the registry is unavailable.
std::string InstallJsClients(std::string* why_not);

}  // namespace cairn::testing
