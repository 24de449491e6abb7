#pragma once

#include <string>
#include <vector>

#include "common/status.h"
#include "daemon/cairnd_options.h"

namespace cairn {

// Loads and validates a cairnd configuration file with `key.path=value` overrides applied. The
// error lists every problem, each with file:line:column (or the --set that caused it) and key.
Expected<CairndOptions> LoadCairndOptions(const std::string& path,
                                          const std::vector<std::string>& overrides);

}  // namespace cairn
