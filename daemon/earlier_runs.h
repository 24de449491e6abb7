#pragma once

// A cairnd restarted on the same output folder (systemd restarts it after a crash or a watchdog
// timeout) would overwrite what the run before left: its recording, the most useful data after a
// crash, and the submaps it finished. Instead, before anything is written, the earlier run's
// outputs move into OUT/earlier-runs/N (N counting up), and the oldest such folders beyond a
// configured number are removed so that a robot's disk stays bounded.

#include <string>
#include <vector>

#include "common/status.h"

namespace cairn {

struct EarlierRunsReport {
  int moved_entries = 0;   // files and folders of the earlier run moved
  std::string kept_in;     // the folder they went to; empty when nothing was moved
  int removed_runs = 0;    // older earlier-run folders removed to stay within `keep`
};

class EarlierRuns {
 public:
  static constexpr const char* kFolder = "earlier-runs";

  // Moves every entry of `dir` except kFolder and those holding a `persistent` path (what lives
  // across runs or is still to be read: the exchange's item store, a dataset being replayed, key
  // files) into dir/earlier-runs/N, then removes the
  // oldest run folders while more than `keep` remain (keep 0: the earlier run is not kept). A
  // missing `dir` has nothing to keep. Entries moved before an error stay moved; a crash
  // half-way leaves the rest to be moved by the next start, into the next folder.
  static Expected<EarlierRunsReport> Keep(const std::string& dir, int keep,
                                          const std::vector<std::string>& persistent);
};

}  // namespace cairn
