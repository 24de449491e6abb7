#pragma once

#include <string>
#include <vector>

#include "tools/cairn_command.h"

namespace cairn::tools {

// CPU time of the calling thread in ms: on a loaded machine it still measures one core's work.
double ThreadCpuMs();
// CPU time of the whole process (all threads) in ms: unlike wall time it barely depends on what
// else runs on the machine, so it still compares work spread over threads when cores are shared.
double ProcessCpuMs();
// Comma-separated finite numbers (at least one) into `out`; false on anything else.
bool ParseNumberList(const std::string& s, std::vector<double>* out);
// -h or --help anywhere among a command's arguments: it prints its usage (PrintUsage) whatever
// else was given, rather than taking the word for a file or an unknown option.
bool WantsHelp(const CommandArgs& args);
// `usage` on standard output; returns 0, the command's exit status.
int PrintUsage(const char* usage);

int RunConfigCheck(const CommandArgs& args);
int RunConfigDoc(const CommandArgs& args);
int RunMcapInfo(const CommandArgs& args);
int RunSummary(const CommandArgs& args);
int RunTrajectoryConvert(const CommandArgs& args);
int RunKeysGenerate(const CommandArgs& args);

}  // namespace cairn::tools

namespace cairn::tools {

int RunStereo(const CommandArgs& args);
int RunStereoEval(const CommandArgs& args);
int RunBenchStereo(const CommandArgs& args);
int RunBenchFpga(const CommandArgs& args);
int RunBenchFilter(const CommandArgs& args);
int RunGraphSolve(const CommandArgs& args);
int RunGraphReplay(const CommandArgs& args);
int RunGraphInject(const CommandArgs& args);
int RunGraphSwitchNees(const CommandArgs& args);
int RunBenchVoScale(const CommandArgs& args);
int RunBenchGraph(const CommandArgs& args);
int RunSim(const CommandArgs& args);
int RunBenchSim(const CommandArgs& args);

}  // namespace cairn::tools

namespace cairn::tools {

int RunMap(const CommandArgs& args);
int RunBenchMap(const CommandArgs& args);
int RunBenchLines(const CommandArgs& args);
int RunBenchLandmarks(const CommandArgs& args);
int RunEval(const CommandArgs& args);
int RunBenchVo(const CommandArgs& args);
int RunMatch(const CommandArgs& args);
int RunDetect(const CommandArgs& args);
int RunBenchDetect(const CommandArgs& args);
int RunDetectBuildLut(const CommandArgs& args);
int RunDetectCheckLut(const CommandArgs& args);
int RunBenchMatch(const CommandArgs& args);
int RunBenchRt(const CommandArgs& args);

}  // namespace cairn::tools
