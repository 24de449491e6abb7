#include "drivers/aravis_camera_options.h"

#include <utility>

namespace cairn {
namespace {

constexpr std::pair<std::string_view, AravisPixelFormat> kPixelFormats[] = {
    {"mono8", AravisPixelFormat::kMono8},        {"mono16", AravisPixelFormat::kMono16},
    {"bayer_rg8", AravisPixelFormat::kBayerRg8}, {"bayer_bg8", AravisPixelFormat::kBayerBg8},
    {"bayer_gb8", AravisPixelFormat::kBayerGb8}, {"bayer_gr8", AravisPixelFormat::kBayerGr8},
};

}  // namespace

Expected<AravisPixelFormat> ParseAravisPixelFormat(std::string_view name) {
  std::string known;
  for (const auto& [n, format] : kPixelFormats) {
    if (n == name) return format;
    known += known.empty() ? std::string(n) : ", " + std::string(n);
  }
  return InvalidArgumentError("pixel_format '" + std::string(name) + "' is not one of " + known);
}

Status AravisCameraOptions::Validate() const {
  if (left.empty() || right.empty()) return InvalidArgumentError("left and right must name the two cameras");
  if (left == right) return InvalidArgumentError("left and right name the same camera '" + left + "'");
  CAIRN_RETURN_IF_ERROR(ParseAravisPixelFormat(pixel_format).status());
  if (trigger == AravisTrigger::kExternal && trigger_source.empty())
    return InvalidArgumentError("trigger_source must name the input line of the external trigger");
  // Beyond half a frame period a frame could pair with its partner's neighbour.
  if (pair_tolerance >= 0.5 / frame_rate_hz)
    return InvalidArgumentError(
        "pair_tolerance " + std::to_string(pair_tolerance) + " s must be below half the frame period (" +
        std::to_string(0.5 / frame_rate_hz) + " s at frame_rate_hz " + std::to_string(frame_rate_hz) + ")");
  return Status::Ok();
}

}  // namespace cairn
