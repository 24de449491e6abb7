#pragma once

#include "tools/cairn_command.h"

namespace cairn::tools {

int RunConfigCheck(const CommandArgs& args);
int RunConfigDoc(const CommandArgs& args);
int RunSim(const CommandArgs& args);
int RunBenchSim(const CommandArgs& args);

}  // namespace cairn::tools
