#pragma once
// The FPGA backend of StereoMatcher: the host driver of the SGM offload (fpga/rtl, register map in
// fpga/REGISTERS.md). It programs one frame through the device's registers, lets the device's DMA
// engine read the pair from and write the disparity to DMA buffers, waits for the interrupt with a
// timeout and checks the status. The device computes the golden model's raster_paths disparity
// bit for bit; the post-filters (median, speckle, hole filling) and depth run here on the CPU,
// with the CPU backends' code, reading the DMA buffer in place.
//
// Errors come back as Status: no device or a different core (NotFound / Unavailable), options the
// core cannot run (InvalidArgument), no interrupt in time (Timeout; the frame is aborted), error
// flags (Internal, naming the flags) and a device that vanished mid-frame (Unavailable).

#include <chrono>
#include <cstdint>
#include <memory>
#include <string_view>
#include <vector>

#include "fpga/stereo_device.h"
#include "stereo/disparity_filter.h"
#include "stereo/sgm_options.h"
#include "stereo/stereo_matcher_interface.h"

namespace cairn {

class FpgaStereoMatcher final : public StereoMatcher {
 public:
  // What the core can do (its CAPS registers).
  struct Capabilities {
    int lanes = 0;             // disparities per clock; num_disparities must be a multiple
    int max_disparities = 0;
    int max_width = 0;
    int max_height = 0;
  };

  static Expected<std::unique_ptr<FpgaStereoMatcher>> Create(
      const SgmOptions& options, std::unique_ptr<StereoDevice> device,
      std::chrono::nanoseconds timeout = std::chrono::milliseconds(500));
  // Whether the core runs these options (the FPGA computes only the raster_paths mode).
  static Status CheckOptions(const SgmOptions& options, const Capabilities& caps);

  std::string_view name() const override { return "fpga"; }
  Status Match(const StereoMatcherInput& input, StereoMatcherOutput* output) override;

  const Capabilities& capabilities() const { return caps_; }
  StereoDevice& device() { return *device_; }
  // Device clock cycles of the last frame, and from its last input pixel to its end.
  uint32_t last_frame_cycles() const { return last_cycles_; }
  uint32_t last_tail_cycles() const { return last_tail_cycles_; }

 private:
  FpgaStereoMatcher(const SgmOptions& options, std::unique_ptr<StereoDevice> device,
                    std::chrono::nanoseconds timeout, const Capabilities& caps);
  Status PrepareBuffers(int width, int height);
  Status RunFrame();

  SgmOptions options_;
  std::unique_ptr<StereoDevice> device_;
  std::chrono::nanoseconds timeout_;
  Capabilities caps_;
  int width_ = 0, height_ = 0;
  size_t src_stride_ = 0, dst_stride_ = 0;
  DmaBuffer left_, right_, disparity_;
  std::vector<int16_t> raw_;  // only when the DMA rows are padded
  DisparityFilter filter_;
  uint32_t last_cycles_ = 0, last_tail_cycles_ = 0;
};

}  // namespace cairn
