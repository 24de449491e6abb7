#pragma once

#include "tools/cairn_command.h"

namespace cairn::tools {

int RunConfigCheck(const CommandArgs& args);
int RunConfigDoc(const CommandArgs& args);
int RunBenchFilter(const CommandArgs& args);

}  // namespace cairn::tools
