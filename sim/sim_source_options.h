#pragma once
// `source: sim`: the daemon's sensors are one robot of a simulated mission (drivers/simulator).
// The robot is the one named like `robot.name`; the other robots of the mission move through the
// same world and show up in its images. Pacing comes from the `replay` section.

#include <string>

#include "common/options_visitor.h"
#include "sim/gnss_simulator_options.h"

namespace cairn {

struct SimSourceOptions {
  std::string world;                     // world YAML; empty = the built-in default world
  std::string robots = "rover,hexacopter";  // every robot of the mission, comma separated
  int64_t seed = 1;                      // replaces the world file's seed
  double duration = 60.0;                // s; the source ends (end of data) after it
  double image_scale = 1.0;              // < 1 shrinks every camera
  int64_t motion_blur_samples = 1;       // > 1 averages instants over the exposure
  int64_t render_threads = 2;            // 2: the right camera renders on a second thread
  bool deploy_from_lander = false;       // every robot starts in front of a lander tag
  GnssSimulatorOptions gnss;             // this robot's GNSS receiver (off by default)

  void Visit(OptionsVisitor& v) {
    v.Text("world", world);
    v.Text("robots", robots);
    v.Integer("seed", seed, 0, int64_t{1} << 62, "");
    v.Number("duration", duration, 0.1, 86400.0, "s");
    v.Number("image_scale", image_scale, 0.05, 1.0, "");
    v.Integer("motion_blur_samples", motion_blur_samples, 1, 64, "");
    v.Integer("render_threads", render_threads, 1, 2, "");
    v.Flag("deploy_from_lander", deploy_from_lander);
    v.Section("gnss", gnss);
  }
};

}  // namespace cairn
