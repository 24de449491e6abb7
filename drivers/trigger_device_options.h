#pragma once
// `trigger:` of a profile: the cameras' trigger line for source: live, and how its edges stamp the
// cameras' frames (trigger_frame_stamper.h). `none`: the frames keep the cameras' own times.

#include "common/options_visitor.h"
#include "drivers/gpiod_trigger_options.h"
#include "drivers/trigger_frame_stamper.h"

namespace cairn {

enum class TriggerDriverKind { kNone, kGpiod };

struct TriggerDeviceOptions {
  TriggerDriverKind driver = TriggerDriverKind::kNone;
  GpiodTriggerOptions gpiod;
  TriggerFrameStamperOptions stamping;

  void Visit(OptionsVisitor& v) {
    v.Choice("driver", driver, {{"none", TriggerDriverKind::kNone}, {"gpiod", TriggerDriverKind::kGpiod}});
    v.Section("gpiod", gpiod);
    v.Section("stamping", stamping);
  }
};

}  // namespace cairn
