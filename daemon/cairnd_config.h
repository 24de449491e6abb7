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

// The effective configuration an earlier run wrote to its output folder, perhaps by an earlier
// version: keys added since keep their defaults and keys removed since are skipped; `notes` gets
// one line per such key. Values out of range and malformed files still fail.
Expected<CairndOptions> LoadEarlierRunOptions(const std::string& path, std::vector<std::string>* notes);

}  // namespace cairn
