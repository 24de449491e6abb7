#pragma once

#include "tools/cairn_command.h"

namespace cairn::tools {

int RunConfigCheck(const CommandArgs& args);
int RunConfigDoc(const CommandArgs& args);
int RunGraphSolve(const CommandArgs& args);
int RunGraphReplay(const CommandArgs& args);
int RunGraphInject(const CommandArgs& args);
int RunBenchGraph(const CommandArgs& args);

}  // namespace cairn::tools
