// cairn bench fpga: one frame through the cycle-accurate model of the SGM offload (driver +
// simulated board), checked against the golden model, with the device's cycle count turned into
// throughput, the clock needed for a frame rate, and the latency in lines.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>

#include <opencv2/imgproc.hpp>

#include "fpga/fpga_stereo_matcher.h"
#include "fpga/simulated_stereo_device.h"
#include "stereo/sgm_matcher.h"
#include "stereo/stereo_image_io.h"
#include "tools/commands.h"

namespace cairn::tools {

constexpr const char* kBenchFpgaUsage =
    "usage: cairn bench fpga [--left L --right R] [--size 1024x508] [--max-disparity 128] [--fps 30]\n";

int RunBenchFpga(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchFpgaUsage);
  std::string left_path, right_path, size = "1024x508";
  int disparities = 128;
  double fps = 30.0;
  for (size_t i = 0; i + 1 < args.args.size(); i += 2) {
    const std::string& k = args.args[i];
    const std::string& v = args.args[i + 1];
    if (k == "--left") left_path = v;
    else if (k == "--right") right_path = v;
    else if (k == "--size") size = v;
    else if (k == "--max-disparity") disparities = std::atoi(v.c_str());
    else if (k == "--fps") fps = std::atof(v.c_str());
    else {
      std::fprintf(stderr, "cairn: unknown option %s\n", k.c_str());
      return 2;
    }
  }
  if (args.args.size() % 2 != 0) {
    std::fputs(kBenchFpgaUsage, stderr);
    return 2;
  }
  const char* env = std::getenv("CAIRN_DATA_DIR");
  const std::string data = env != nullptr ? env : "../shared/data";
  if (left_path.empty()) left_path = data + "/stereo/middlebury2014q-motorcycle/im0.png";
  if (right_path.empty()) right_path = data + "/stereo/middlebury2014q-motorcycle/im1.png";
  int width = 0, height = 0;
  if (std::sscanf(size.c_str(), "%dx%d", &width, &height) != 2 || width < 8 || height < 4) {
    std::fprintf(stderr, "cairn: --size must look like 1024x508\n");
    return 2;
  }
  auto pair = LoadGrayPair(left_path, right_path);
  if (!pair.ok()) {
    std::fprintf(stderr, "cairn: %s\n", pair.status().message().c_str());
    return 1;
  }
  cv::Mat left, right;
  cv::resize(pair->left, left, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  cv::resize(pair->right, right, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  StereoMatcherInput in;
  in.left = left.data;
  in.right = right.data;
  in.width = width;
  in.height = height;
  in.stride = static_cast<int>(left.step[0]);

  SgmOptions o;
  o.raster_paths = true;
  o.num_disparities = disparities;
  o.median = false;  // compare the device's own output
  o.speckle_max_size = 0;
  auto fpga = FpgaStereoMatcher::Create(o, std::make_unique<SimulatedStereoDevice>(),
                                        std::chrono::seconds(600));
  if (!fpga.ok()) {
    std::fprintf(stderr, "cairn: %s\n", fpga.status().message().c_str());
    return 1;
  }
  StereoMatcherOutput rtl, golden, simd;
  const auto t0 = std::chrono::steady_clock::now();
  const Status s = (*fpga)->Match(in, &rtl);
  const auto t1 = std::chrono::steady_clock::now();
  if (!s.ok()) {
    std::fprintf(stderr, "cairn: %s\n", s.message().c_str());
    return 1;
  }
  o.backend = SgmBackend::kScalar;
  auto scalar = SgmMatcher::Create(o);
  if (!scalar.ok() || !(*scalar)->Match(in, &golden).ok()) return 1;
  o.backend = SgmBackend::kSimd;
  o.threads = 1;
  auto vec = SgmMatcher::Create(o);
  const auto t2 = std::chrono::steady_clock::now();
  if (!vec.ok() || !(*vec)->Match(in, &simd).ok()) return 1;
  const auto t3 = std::chrono::steady_clock::now();

  const auto& caps = (*fpga)->capabilities();
  const double cycles = (*fpga)->last_frame_cycles();
  const double groups = static_cast<double>(disparities) / caps.lanes;
  const double pixels = static_cast<double>(width) * height;
  const double line_cycles = width * groups;
  const double sim_s = std::chrono::duration<double>(t1 - t0).count();
  std::printf("bench fpga: %dx%d, %d disparities, core with %d lanes (%g groups per pixel)\n",
              width, height, disparities, caps.lanes, groups);
  std::printf("  device cycles per frame     %.0f\n", cycles);
  std::printf("  cycles per pixel per group  %.4f\n", cycles / (pixels * groups));
  std::printf("  clock for %.0f Hz            %.1f MHz\n", fps, cycles * fps / 1e6);
  std::printf("  frame rate at 100/150/200 MHz  %.1f / %.1f / %.1f Hz\n", 100e6 / cycles,
              150e6 / cycles, 200e6 / cycles);
  std::printf("  latency last input pixel -> done  %u cycles = %.2f lines\n",
              (*fpga)->last_tail_cycles(), (*fpga)->last_tail_cycles() / line_cycles);
  std::printf("  bit-exact vs golden (scalar raster_paths): %s; SIMD raster_paths: %s\n",
              rtl.disparity == golden.disparity ? "yes" : "NO",
              simd.disparity == golden.disparity ? "yes" : "NO");
  std::printf("  cosimulation wall time %.2f s (%.0f simulated cycles/s); CPU SIMD raster, 1 "
              "thread: %.1f ms\n",
              sim_s, static_cast<double>((*fpga)->last_frame_cycles()) / sim_s,
              std::chrono::duration<double, std::milli>(t3 - t2).count());
  return rtl.disparity == golden.disparity ? 0 : 1;
}

}  // namespace cairn::tools
