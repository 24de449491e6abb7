#pragma once
// `trigger.gpiod:` of a profile: the stereo cameras' trigger on a GPIO line through libgpiod
// (gpiod_trigger.h). The input line carries one edge per exposure (the cameras' strobe output, or
// the trigger line itself looped back); an optional output line emits the trigger pulses.

#include <cstdint>
#include <string>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

enum class GpioEdge { kRising, kFalling };
// The input's bias resistor; opto-isolated strobe outputs (open collector) need a pull-up.
enum class GpioBias { kAsIs, kPullUp, kPullDown, kDisabled };

struct GpiodTriggerOptions {
  // The GPIO chip: its name (gpiochip0), path (/dev/gpiochip0), label or number. Empty: the chip
  // that has a line named `line`.
  std::string chip = "gpiochip0";
  std::string line = "0";  // the input: an offset on the chip, or the line's name
  GpioEdge edge = GpioEdge::kRising;
  GpioBias bias = GpioBias::kAsIs;
  // Where to emit pulses (an offset or a name on the same chip); empty: only listen, the cameras
  // free-run or something else triggers them.
  std::string output_line = "";
  // Pulses per second on output_line, and the rate the edges are expected at: a gap longer than
  // 1.5 periods counts the edges lost in it. 0: unknown (free-running cameras), no pulses.
  double rate_hz = 0.0;
  double pulse_width = 0.001;  // s the output stays high
  double timeout = 1.0;        // s without an edge while the line is open: a fault
  double reopen_interval = 1.0;  // s between attempts to open a chip that is missing or vanished

  void Visit(OptionsVisitor& v) {
    v.Text("chip", chip);
    v.Text("line", line);
    v.Choice("edge", edge, {{"rising", GpioEdge::kRising}, {"falling", GpioEdge::kFalling}});
    v.Choice("bias", bias,
             {{"as_is", GpioBias::kAsIs}, {"pull_up", GpioBias::kPullUp}, {"pull_down", GpioBias::kPullDown},
              {"disabled", GpioBias::kDisabled}});
    v.Text("output_line", output_line);
    v.Number("rate_hz", rate_hz, 0.0, 1000.0, "Hz");
    v.Number("pulse_width", pulse_width, 1e-6, 1.0, "s");
    v.Number("timeout", timeout, 0.01, 60.0, "s");
    v.Number("reopen_interval", reopen_interval, 0.01, 60.0, "s");
  }
  // A line to listen on, an output apart from it, and pulses shorter than their period.
  Status Validate() const;
};

}  // namespace cairn
