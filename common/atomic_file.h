#pragma once

#include <string>

#include "common/status.h"

namespace cairn {

// Writes `contents` to `path` through a temporary file in the same folder, fsync and rename, so a
// reader (or a crash) sees either the old file or the complete new one, never a partial one.
Status WriteFileAtomically(const std::string& path, const std::string& contents);

}  // namespace cairn
