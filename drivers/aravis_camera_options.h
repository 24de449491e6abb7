#pragma once
// `stereo:` of a profile whose cameras are a pair of GigE Vision cameras read through Aravis
// (aravis_stereo_camera.h). Both cameras get the same settings.

#include <cstdint>
#include <string>
#include <string_view>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

// The pixel formats the driver reads; every one is published as gray8 (Mono8 without a copy).
enum class AravisPixelFormat { kMono8, kMono16, kBayerRg8, kBayerBg8, kBayerGb8, kBayerGr8 };

// "mono8", "mono16", "bayer_rg8", "bayer_bg8", "bayer_gb8", "bayer_gr8".
Expected<AravisPixelFormat> ParseAravisPixelFormat(std::string_view name);

enum class AravisTrigger { kFreeRunning, kExternal };

struct AravisCameraOptions {
  // Aravis device ids: an IP address, "vendor-model-serial", "vendor-serial" or the user id (the
  // last three need broadcast discovery on the camera's network).
  std::string left = "";
  std::string right = "";
  // One of the names ParseAravisPixelFormat takes; checked by Validate().
  std::string pixel_format = "mono8";
  int64_t width = 0;   // px; 0: the device's current width
  int64_t height = 0;  // px; 0: the device's current height
  // Free running: the rate set on the cameras. External trigger: the rate the trigger is expected
  // at (how long a frame waits for its partner).
  double frame_rate_hz = 20.0;
  AravisTrigger trigger = AravisTrigger::kFreeRunning;
  std::string trigger_source = "Line1";  // the input line of `external` (and of SetTriggerMode)
  double exposure = 0.0;                 // s; 0: the cameras' automatic exposure
  int64_t buffers = 8;  // per camera, reused; a consumer holding all of them stalls the stream
  // Receive the stream through a packet socket ring (needs CAP_NET_RAW; else a UDP socket).
  bool packet_socket = true;
  bool packet_resend = true;      // ask the camera to resend missing GVSP packets
  double packet_timeout = 0.02;   // s before a missing packet is asked again
  double frame_retention = 0.1;   // s an incomplete frame waits for its last packets
  double frame_timeout = 1.0;     // s without a frame: a timeout fault, and the camera is probed
  double reopen_interval = 1.0;   // s between attempts to open a camera that vanished
  double pair_tolerance = 0.002;  // s, largest difference of the two cameras' frame times in a pair

  void Visit(OptionsVisitor& v) {
    v.Text("left", left);
    v.Text("right", right);
    v.Text("pixel_format", pixel_format);
    v.Integer("width", width, 0, 65535, "px");
    v.Integer("height", height, 0, 65535, "px");
    v.Number("frame_rate_hz", frame_rate_hz, 0.1, 1000.0, "Hz");
    v.Choice("trigger", trigger,
             {{"free_running", AravisTrigger::kFreeRunning}, {"external", AravisTrigger::kExternal}});
    v.Text("trigger_source", trigger_source);
    v.Number("exposure", exposure, 0.0, 10.0, "s");
    v.Integer("buffers", buffers, 2, 256, "buffers");
    v.Flag("packet_socket", packet_socket);
    v.Flag("packet_resend", packet_resend);
    v.Number("packet_timeout", packet_timeout, 0.0001, 10.0, "s");
    v.Number("frame_retention", frame_retention, 0.001, 10.0, "s");
    v.Number("frame_timeout", frame_timeout, 0.01, 60.0, "s");
    v.Number("reopen_interval", reopen_interval, 0.01, 60.0, "s");
    v.Number("pair_tolerance", pair_tolerance, 0.0, 1.0, "s");
  }
  Status Validate() const;
};

}  // namespace cairn
