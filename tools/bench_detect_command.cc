// cairn bench detect: AprilTag detection time on rover camera frames of the simulator's default
// world with a tag36h11 tag drawn in at 2 to 8 m: the whole frame (libapriltag's defaults:
// decimate 2, one thread; and at full resolution) and a region of interest around the tag, as the
// daemon would search where the graph predicts a teammate.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "detection/tag_detector.h"
#include "detection/testing/rendered_tag.h"
#include "sim/mission_simulator.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

struct Series {
  std::string name;
  std::vector<double> ms;
  int found = 0;
};

void Print(const Series& s, size_t frames) {
  std::vector<double> v = s.ms;
  std::sort(v.begin(), v.end());
  std::printf("  %-44s median %6.2f ms (min %6.2f, max %6.2f); tag found in %d of %zu\n", s.name.c_str(),
              v[v.size() / 2], v.front(), v.back(), s.found, frames);
}

}  // namespace

constexpr const char* kBenchDetectUsage =
    "usage: cairn bench detect [--frames N (16)]\n";

int RunBenchDetect(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchDetectUsage);
  int frames = 16;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    std::vector<double> n;
    if (a == "--frames" && i + 1 < args.args.size() && ParseNumberList(args.args[i + 1], &n) && n.size() == 1 &&
        n[0] >= 4 && n[0] <= 1000) {
      frames = static_cast<int>(n[0]);
      ++i;
    } else {
      std::fputs(kBenchDetectUsage, stderr);
      return 2;
    }
  }
  sim::WorldOptions world;
  sim::MissionOptions mission;
  mission.robots = {"rover"};
  mission.duration = 4.0 * frames + 10.0;
  auto simulator = sim::MissionSimulator::Create(world, mission);
  if (!simulator.ok()) {
    std::fprintf(stderr, "cairn bench detect: %s\n", simulator.status().message().c_str());
    return 1;
  }
  const PinholeRadTan& camera = (*simulator)->robots()[0].stereo.left.intrinsics;
  TagDetectorOptions defaults;  // libapriltag's defaults
  TagDetectorOptions full = defaults;
  full.decimate = 1.0;
  TagDetector detect_defaults(defaults), detect_full(full), detect_roi(full);
  Series s_defaults{"whole frame, decimate 2 (libapriltag defaults)", {}, 0};
  Series s_full{"whole frame, decimate 1", {}, 0};
  Series s_roi{"region of interest (3x the tag), decimate 1", {}, 0};
  std::vector<uint8_t> left, right;
  using Clock = std::chrono::steady_clock;
  const auto timed = [&](TagDetector& d, const Image& image, const PixelBox* roi, Series* s) {
    const auto t0 = Clock::now();
    const auto r = d.Detect(image, roi);
    s->ms.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    if (r.ok()) s->found += std::any_of(r->begin(), r->end(), [](const TagDetection& t) { return t.id == 3; });
  };
  for (int i = 0; i < frames; ++i) {
    (*simulator)->RenderStereo(0, 4.0 + 4.0 * i, static_cast<uint64_t>(i), &left, &right);
    cv::Mat frame(camera.height, camera.width, CV_8UC1, left.data());
    frame = frame.clone();
    // The tag 2, 4, 6 or 8 m ahead, off the axis and turned a little.
    const double d = 2.0 + 2.0 * (i % 4);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(0.15 * d * ((i % 3) - 1), 0.05 * d, d);
    T.linear() = Eigen::AngleAxisd(0.3 * ((i % 5) - 2), Eigen::Vector3d::UnitY()).toRotationMatrix();
    testing::DrawTag(frame, 3, 0.16, T, camera);
    const Image image = testing::ImageOf(frame);
    const Eigen::Vector2d c = camera.Project(T.translation());
    const int half = std::max(32, static_cast<int>(1.5 * camera.fx * 0.16 / d));
    PixelBox roi{std::clamp(static_cast<int>(c.x()) - half, 0, camera.width - 2 * half),
                 std::clamp(static_cast<int>(c.y()) - half, 0, camera.height - 2 * half), 2 * half, 2 * half};
    timed(detect_defaults, image, nullptr, &s_defaults);
    timed(detect_full, image, nullptr, &s_full);
    timed(detect_roi, image, &roi, &s_roi);
  }
  std::printf("cairn bench detect: %d rover frames %dx%d (default world), a 0.16 m tag at 2-8 m, 1 thread\n", frames,
              camera.width, camera.height);
  Print(s_defaults, static_cast<size_t>(frames));
  Print(s_full, static_cast<size_t>(frames));
  Print(s_roi, static_cast<size_t>(frames));
  std::printf("  targets: whole frame <= 20 ms, region of interest <= 3 ms\n");
  return 0;
}

}  // namespace cairn::tools
