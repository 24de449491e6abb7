#pragma once
// team.json: what this robot's exchange did and what its graph makes of the team. Per peer the
// bytes and items both ways (means over the run), per robot its items by kind, whether the graph
// has tied it to this robot's frame, and the connected components.

#include <string>

#include "daemon/comms/comms_stage.h"
#include "daemon/pipeline/graph_stage.h"

namespace cairn {

std::string BuildTeamJson(const TeamReport& report, const TeamFile& team, const GraphStage* graph);

}  // namespace cairn
