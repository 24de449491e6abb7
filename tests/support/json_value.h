#pragma once
// Tests read JSON with the daemon's reader.

#include "daemon/json_value.h"

namespace cairn::testing {
using cairn::JsonValue;
}  // namespace cairn::testing
