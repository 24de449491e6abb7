#pragma once
// Tests read JSON with the daemon's reader.

#include "common/json_value.h"

namespace cairn::testing {
using cairn::JsonValue;
}  // namespace cairn::testing
