#pragma once

#include <string>

#include "common/options_visitor.h"

namespace cairn {

enum class ReplayPacing { kRealTime, kScaled, kFastAsPossible };

struct ReplayOptions {
  // An EuRoC/ASL folder (the one holding mav0/), or a cairnd recording (an .mcap file or a folder
  // of recording-NNN.mcap). Empty means "given with --replay".
  std::string dataset;
  ReplayPacing pacing = ReplayPacing::kFastAsPossible;
  // Playback speed for `scaled` pacing: 2 plays twice as fast as recorded.
  double speed = 1.0;
  // Every sample is consumed by the whole pipeline before the next is published, in timestamp
  // order, so that a run is reproducible bit for bit (throughput is that of the slowest stage).
  bool deterministic = true;

  void Visit(OptionsVisitor& v) {
    v.Text("dataset", dataset);
    v.Choice("pacing", pacing, {{"realtime", ReplayPacing::kRealTime},
                                {"scaled", ReplayPacing::kScaled},
                                {"fast", ReplayPacing::kFastAsPossible}});
    v.Number("speed", speed, 0.01, 1000.0, "x recorded rate");
    v.Flag("deterministic", deterministic);
  }
};

}  // namespace cairn
