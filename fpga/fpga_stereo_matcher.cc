#include "fpga/fpga_stereo_matcher.h"

#include <cstring>
#include <string>

#include "fpga/sgm_registers.h"
#include "stereo/stereo_depth.h"

namespace cairn {
namespace {

constexpr uint32_t kGone = 0xFFFFFFFFu;

size_t RoundUp8(size_t v) { return (v + 7) / 8 * 8; }

std::string Hex(uint32_t v) {
  char buf[16];
  std::snprintf(buf, sizeof(buf), "0x%08x", v);
  return buf;
}

std::string FlagNames(uint32_t status) {
  std::string s;
  const auto add = [&s](const char* name) { s += (s.empty() ? "" : ", ") + std::string(name); };
  if (status & sgm_reg::kStatusConfigError) add("configuration rejected");
  if (status & sgm_reg::kStatusDmaReadError) add("DMA read error");
  if (status & sgm_reg::kStatusDmaWriteError) add("DMA write error");
  if (status & sgm_reg::kStatusOverrun) add("start while busy");
  return s.empty() ? "unknown error" : s;
}

}  // namespace

Status FpgaStereoMatcher::CheckOptions(const SgmOptions& o, const Capabilities& caps) {
  CAIRN_RETURN_IF_ERROR(o.Validate());
  if (!o.raster_paths) {
    return InvalidArgumentError("fpga stereo computes only sgm raster_paths: true (FPGA mode)");
  }
  if (o.census_width != 5 || o.census_height != 5) {
    return InvalidArgumentError("fpga stereo has a 5x5 census, got " +
                                std::to_string(o.census_width) + "x" +
                                std::to_string(o.census_height));
  }
  if (o.min_disparity != 0) {
    return InvalidArgumentError("fpga stereo needs min_disparity 0, got " +
                                std::to_string(o.min_disparity));
  }
  if (caps.lanes <= 0 || o.num_disparities % caps.lanes != 0 ||
      o.num_disparities > caps.max_disparities) {
    return InvalidArgumentError("fpga stereo needs num_disparities a multiple of " +
                                std::to_string(caps.lanes) + " up to " +
                                std::to_string(caps.max_disparities) + ", got " +
                                std::to_string(o.num_disparities));
  }
  if (o.lr_max_diff > 31) {
    return InvalidArgumentError("fpga stereo needs lr_max_diff <= 31");
  }
  return Status::Ok();
}

Expected<std::unique_ptr<FpgaStereoMatcher>> FpgaStereoMatcher::Create(
    const SgmOptions& options, std::unique_ptr<StereoDevice> device,
    std::chrono::nanoseconds timeout) {
  if (device == nullptr) return UnavailableError("fpga stereo: no device");
  const uint32_t id = device->Read32(sgm_reg::kId);
  if (id == kGone) {
    return UnavailableError("fpga stereo: " + std::string(device->name()) +
                            " does not answer (register reads return all ones)");
  }
  if (id != sgm_reg::kIdValue) {
    return NotFoundError("fpga stereo: " + std::string(device->name()) + " has ID " + Hex(id) +
                         ", not the SGM core (" + Hex(sgm_reg::kIdValue) + ")");
  }
  const uint32_t version = device->Read32(sgm_reg::kVersion);
  if (version >> 16 != sgm_reg::kVersionMajor) {
    return FailedPreconditionError("fpga stereo: core version " + Hex(version) +
                                   ", the driver needs major " +
                                   std::to_string(sgm_reg::kVersionMajor));
  }
  Capabilities caps;
  const uint32_t lanes = device->Read32(sgm_reg::kCapsLanes);
  const uint32_t size = device->Read32(sgm_reg::kCapsSize);
  caps.lanes = static_cast<int>(lanes >> 16);
  caps.max_disparities = static_cast<int>(lanes & 0xFFFF);
  caps.max_width = static_cast<int>(size & 0xFFFF);
  caps.max_height = static_cast<int>(size >> 16);
  CAIRN_RETURN_IF_ERROR(CheckOptions(options, caps));
  auto m = std::unique_ptr<FpgaStereoMatcher>(
      new FpgaStereoMatcher(options, std::move(device), timeout, caps));
  // Frame-independent registers once.
  StereoDevice& d = *m->device_;
  uint8_t table[256];
  options.FillP2Table(table);
  for (int i = 0; i < 256; ++i) d.Write32(sgm_reg::kP2Table + 4 * i, table[i]);
  d.Write32(sgm_reg::kNumDisparities, static_cast<uint32_t>(options.num_disparities));
  d.Write32(sgm_reg::kP1, static_cast<uint32_t>(options.p1));
  d.Write32(sgm_reg::kUniqueness, static_cast<uint32_t>(options.uniqueness_percent));
  d.Write32(sgm_reg::kLrCheck, (options.lr_check ? 1u : 0u) |
                                   static_cast<uint32_t>(options.lr_max_diff) << 8);
  d.Write32(sgm_reg::kSubpixel, options.subpixel ? 1u : 0u);
  return m;
}

FpgaStereoMatcher::FpgaStereoMatcher(const SgmOptions& options,
                                     std::unique_ptr<StereoDevice> device,
                                     std::chrono::nanoseconds timeout, const Capabilities& caps)
    : options_(options), device_(std::move(device)), timeout_(timeout), caps_(caps) {}

Status FpgaStereoMatcher::PrepareBuffers(int width, int height) {
  device_->ReleaseDma();
  width_ = height_ = 0;
  src_stride_ = RoundUp8(static_cast<size_t>(width));
  dst_stride_ = RoundUp8(2 * static_cast<size_t>(width));
  const size_t h = static_cast<size_t>(height);
  auto l = device_->AllocateDma(src_stride_ * h);
  if (!l.ok()) return l.status().WithContext("fpga stereo: left image buffer");
  auto r = device_->AllocateDma(src_stride_ * h);
  if (!r.ok()) return r.status().WithContext("fpga stereo: right image buffer");
  auto d = device_->AllocateDma(dst_stride_ * h);
  if (!d.ok()) return d.status().WithContext("fpga stereo: disparity buffer");
  left_ = *l;
  right_ = *r;
  disparity_ = *d;
  raw_.assign(dst_stride_ == 2 * static_cast<size_t>(width) ? 0 : static_cast<size_t>(width) * h,
              0);
  width_ = width;
  height_ = height;
  StereoDevice& dev = *device_;
  dev.Write32(sgm_reg::kWidth, static_cast<uint32_t>(width));
  dev.Write32(sgm_reg::kHeight, static_cast<uint32_t>(height));
  const auto split = [&dev](uint32_t lo, uint64_t v) {
    dev.Write32(lo, static_cast<uint32_t>(v));
    dev.Write32(lo + 4, static_cast<uint32_t>(v >> 32));
  };
  split(sgm_reg::kSrcLeftLo, left_.iova);
  split(sgm_reg::kSrcRightLo, right_.iova);
  split(sgm_reg::kDstLo, disparity_.iova);
  dev.Write32(sgm_reg::kSrcStride, static_cast<uint32_t>(src_stride_));
  dev.Write32(sgm_reg::kDstStride, static_cast<uint32_t>(dst_stride_));
  return Status::Ok();
}

Status FpgaStereoMatcher::RunFrame() {
  StereoDevice& d = *device_;
  d.Write32(sgm_reg::kIrqStatus, sgm_reg::kIrqDone | sgm_reg::kIrqError);
  d.Write32(sgm_reg::kControl, sgm_reg::kControlIrqEnable | sgm_reg::kControlStart);
  const Status wait = d.WaitForInterrupt(timeout_);
  const uint32_t status = d.Read32(sgm_reg::kStatus);
  if (status == kGone || wait.code() == StatusCode::kUnavailable) {
    return UnavailableError("fpga stereo: " + std::string(d.name()) + " removed during a frame" +
                            (wait.ok() ? "" : " (" + wait.message() + ")"));
  }
  if (!wait.ok()) {
    // Stop the DMA engine before the buffers are reused.
    d.Write32(sgm_reg::kControl, sgm_reg::kControlAbort);
    return TimeoutError("fpga stereo: frame not finished (status " + Hex(status) + "): " +
                        wait.message());
  }
  if (status & sgm_reg::kStatusError) {
    return InternalError("fpga stereo: device reports " + FlagNames(status) + " (status " +
                         Hex(status) + ")");
  }
  if (!(status & sgm_reg::kStatusDone)) {
    return InternalError("fpga stereo: interrupt without done (status " + Hex(status) + ")");
  }
  last_cycles_ = d.Read32(sgm_reg::kCycles);
  last_tail_cycles_ = d.Read32(sgm_reg::kTailCycles);
  d.Write32(sgm_reg::kIrqStatus, sgm_reg::kIrqDone);
  return Status::Ok();
}

Status FpgaStereoMatcher::Match(const StereoMatcherInput& input, StereoMatcherOutput* output) {
  if (output == nullptr) return InvalidArgumentError("FpgaStereoMatcher::Match: output is null");
  if (input.left == nullptr || input.right == nullptr) {
    return InvalidArgumentError("FpgaStereoMatcher::Match: left or right image is null");
  }
  if (input.width < 1 || input.height < 1 || input.width > caps_.max_width ||
      input.height > caps_.max_height) {
    // Not the caller's fault: the CPU backends take any size.
    return OutOfRangeError("FpgaStereoMatcher::Match: image size " +
                                std::to_string(input.width) + "x" + std::to_string(input.height) +
                                " outside the core's 1..." + std::to_string(caps_.max_width) + "x" +
                                std::to_string(caps_.max_height));
  }
  if (input.stride < input.width) {
    return InvalidArgumentError("FpgaStereoMatcher::Match: stride " +
                                std::to_string(input.stride) + " is smaller than the width " +
                                std::to_string(input.width));
  }
  if (input.width != width_ || input.height != height_) {
    CAIRN_RETURN_IF_ERROR(PrepareBuffers(input.width, input.height));
  }
  const int w = width_, h = height_;
  // UIO cannot map the caller's pages for DMA, so the pair is copied into the DMA buffers.
  for (int y = 0; y < h; ++y) {
    const size_t src = static_cast<size_t>(y) * static_cast<size_t>(input.stride);
    std::memcpy(left_.cpu + y * src_stride_, input.left + src, static_cast<size_t>(w));
    std::memcpy(right_.cpu + y * src_stride_, input.right + src, static_cast<size_t>(w));
  }
  CAIRN_RETURN_IF_ERROR(RunFrame());

  ResizeStereoOutput(w, h, output);
  const size_t n = static_cast<size_t>(w) * h;
  // The device wrote little-endian int16 rows; unpadded rows are used in place.
  const int16_t* raw = reinterpret_cast<const int16_t*>(disparity_.cpu);
  if (!raw_.empty()) {
    for (int y = 0; y < h; ++y) {
      std::memcpy(raw_.data() + static_cast<size_t>(y) * w, disparity_.cpu + y * dst_stride_,
                  2 * static_cast<size_t>(w));
    }
    raw = raw_.data();
  }
  int16_t* disp = output->disparity.data();
  if (options_.median) {
    DisparityFilter::Median3x3(raw, disp, w, h, 0, h);
  } else {
    std::memcpy(disp, raw, n * sizeof(int16_t));
  }
  filter_.RemoveSpeckles(disp, w, h, static_cast<int>(options_.speckle_max_size),
                         static_cast<int>(options_.speckle_max_diff));
  if (options_.fill_holes) {
    for (int y = 0; y < h; ++y) DisparityFilter::FillHolesRow(disp + static_cast<size_t>(y) * w, w);
  }
  ComputeStereoDepth(input, options_.pixel_error_px, output, 0, h);
  return Status::Ok();
}

}  // namespace cairn
