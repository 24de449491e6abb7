// cairn bench lines: line segments of rendered rover keyframes of the structures world (a drive
// around the lander), triangulated with our SGM's disparity. Times detection and triangulation per
// keyframe (SGM runs once per pair, untimed) beside one OpenCV Sobel pass over the same image in
// the same run, and scores the triangulated ends against the world's true surfaces.

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <Eigen/Eigenvalues>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>

#include "mapping/line_segment_detector.h"
#include "mapping/stereo_line_triangulator.h"
#include "sim/surface_distance.h"
#include "sim/testing/structure_stereo_scene.h"
#include "sim/world_file.h"
#include "stereo/sgm_matcher.h"
#include "tools/commands.h"
#include "tools/sample_median.h"

namespace cairn::tools {
namespace {

using LineClock = std::chrono::steady_clock;

double LineMs(LineClock::time_point a, LineClock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

struct LineTimes {
  std::vector<double> wall, cpu;
  void Add(double w, double c) {
    wall.push_back(w);
    cpu.push_back(c);
  }
};

void PrintLineTimes(const char* name, const LineTimes& t) {
  std::printf("  %-28s wall median %6.3f ms, p90 %6.3f ms; CPU median %6.3f ms, p90 %6.3f ms\n", name,
              Median(t.wall), NearestRankPercentile(t.wall, 0.9), Median(t.cpu),
              NearestRankPercentile(t.cpu, 0.9));
}

}  // namespace

constexpr const char* kBenchLinesUsage =
    "usage: cairn bench lines [--frames K (12)] [--repeats R (5)] [--world FILE "
    "(configs/worlds/structures.yaml)]\n";

int RunBenchLines(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchLinesUsage);
  int frames = 12, repeats = 5;
  std::string world_path = "configs/worlds/structures.yaml";
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    std::vector<double> n;
    if ((a == "--frames" || a == "--repeats") && i + 1 < args.args.size() &&
        ParseNumberList(args.args[i + 1], &n) && n.size() == 1 && n[0] >= 1 && n[0] <= 1000) {
      (a == "--frames" ? frames : repeats) = static_cast<int>(n[0]);
      ++i;
    } else if (a == "--world" && i + 1 < args.args.size()) {
      world_path = args.args[++i];
    } else {
      std::fputs(kBenchLinesUsage, stderr);
      return 2;
    }
  }
  auto world = sim::LoadWorldFile(world_path);
  if (!world.ok()) {
    std::fprintf(stderr, "cairn bench lines: %s\n", world.status().ToString().c_str());
    return 1;
  }
  sim::MissionOptions mission;
  mission.duration = 1.0;
  auto simulator = sim::MissionSimulator::Create(*world, mission);
  if (!simulator.ok()) {
    std::fprintf(stderr, "cairn bench lines: %s\n", simulator.status().ToString().c_str());
    return 1;
  }
  const sim::SurfaceDistance surface(**simulator, 1.0);
  const StereoCamera cam = testing::RoverCamera(1.0);  // configs/rover.yaml's cameras
  const PinholeRadTan& k = cam.intrinsics;
  auto matcher = SgmMatcher::Create(SgmOptions{});
  if (!matcher.ok()) {
    std::fprintf(stderr, "cairn bench lines: %s\n", matcher.status().ToString().c_str());
    return 1;
  }
  // The baseline below is one thread, like the stages it is compared with.
  cv::setNumThreads(1);
  const LineSegmentOptions detector_options;
  const StereoLineOptions triangulator_options;
  LineSegmentDetector detector(detector_options);
  StereoLineTriangulator triangulator(triangulator_options, cam);
  std::printf(
      "cairn bench lines: %d keyframes %dx%d (f %.0f px, b %.2f m) of %s along a 3.4 m drive around the "
      "lander; %d timed runs each, 1 thread (%u hardware threads)\n",
      frames, k.width, k.height, k.fx, cam.baseline, world_path.c_str(), repeats,
      std::thread::hardware_concurrency());

  LineTimes detect, triangulate, total, sobel;
  std::vector<double> found, triangulated, ratio;
  std::vector<double> distance_sigmas;  // each end's surface distance over its largest sigma
  LineSegmentDetector::Stats detect_stats;
  StereoLineTriangulator::Stats st, sum_stats;
  int both = 0, one_side = 0;
  std::vector<ImageLineSegment> segments;
  std::vector<StereoLineSegment> lines;
  cv::Mat gradient;
  for (int i = 0; i < frames; ++i) {
    testing::StructureStereoFrame frame;
    testing::RenderStructureFrame(**simulator, cam,
                                  testing::StructureDrivePose((*simulator)->terrain(), i, frames),
                                  static_cast<uint64_t>(i), &frame);
    const StereoMatcherInput in{
        frame.left.data(), frame.right.data(), k.width, k.height, k.width, k.fx, cam.baseline, 0.0};
    StereoMatcherOutput disparity;
    if (Status s = (*matcher)->Match(in, &disparity); !s.ok()) {
      std::fprintf(stderr, "cairn bench lines: %s\n", s.ToString().c_str());
      return 1;
    }
    const cv::Mat image(k.height, k.width, CV_8UC1, frame.left.data());
    for (int r = 0; r < repeats; ++r) {
      auto t0 = LineClock::now();
      double c0 = ThreadCpuMs();
      cv::Sobel(image, gradient, CV_16S, 1, 0, 3);
      sobel.Add(LineMs(t0, LineClock::now()), ThreadCpuMs() - c0);
      t0 = LineClock::now();
      c0 = ThreadCpuMs();
      if (!detector.Detect(frame.left.data(), k.width, k.height, k.width, &segments, &detect_stats)) return 1;
      const auto t1 = LineClock::now();
      const double c1 = ThreadCpuMs();
      if (!triangulator.Triangulate(segments, disparity, &lines, &st)) return 1;
      const auto t2 = LineClock::now();
      const double c2 = ThreadCpuMs();
      detect.Add(LineMs(t0, t1), c1 - c0);
      triangulate.Add(LineMs(t1, t2), c2 - c1);
      total.Add(LineMs(t0, t2), c2 - c0);
      ratio.push_back((c2 - c0) / std::max(1e-6, sobel.cpu.back()));
    }
    found.push_back(static_cast<double>(segments.size()));
    triangulated.push_back(static_cast<double>(lines.size()));
    sum_stats.no_depth += st.no_depth;
    sum_stats.ambiguous += st.ambiguous;
    sum_stats.too_far += st.too_far;
    for (const StereoLineSegment& l : lines) {
      (l.side == LineDepthSide::kBoth ? both : one_side) += 1;
      for (int e = 0; e < 2; ++e) {
        const Eigen::Matrix3d& cov = e == 0 ? l.cov0 : l.cov1;
        const double sigma =
            std::sqrt(Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(cov).eigenvalues().maxCoeff());
        // 1 cm for the surface search's own resolution.
        const double radius = 5.0 * sigma + 0.01;
        const double d = surface.Distance(frame.T_world_cam * (e == 0 ? l.p0 : l.p1), radius);
        distance_sigmas.push_back(std::max(0.0, d - 0.01) / sigma);
      }
    }
  }
  PrintLineTimes("detection", detect);
  PrintLineTimes("triangulation", triangulate);
  PrintLineTimes("detection + triangulation", total);
  PrintLineTimes("baseline: one cv::Sobel pass", sobel);
  std::printf("  ratio (detection + triangulation) / Sobel pass, CPU: median %.1f, p90 %.1f\n", Median(ratio),
              NearestRankPercentile(ratio, 0.9));
  const double median_total = Median(total.cpu);
  std::printf("  target <= 5 ms per keyframe: median CPU %.2f ms, p90 %.2f ms (%s)\n", median_total,
              NearestRankPercentile(total.cpu, 0.9), median_total <= 5.0 ? "met" : "NOT met");
  std::printf(
      "  segments per keyframe (min length %.0f px): median %.0f (min %.0f, max %.0f); triangulated median "
      "%.0f "
      "(%d on both sides of the edge, %d on one; rejected over all keyframes: %d without depth, %d "
      "ambiguous, "
      "%d too far)\n",
      detector_options.min_length_px, Median(found), *std::min_element(found.begin(), found.end()),
      *std::max_element(found.begin(), found.end()), Median(triangulated), both, one_side, sum_stats.no_depth,
      sum_stats.ambiguous, sum_stats.too_far);
  const auto within = [&](double n) {
    return static_cast<double>(std::count_if(distance_sigmas.begin(), distance_sigmas.end(),
                                             [&](double v) { return v <= n; })) /
           std::max<double>(1.0, static_cast<double>(distance_sigmas.size()));
  };
  std::printf(
      "  ends against the true surfaces (sim/surface_distance.h), in sigmas of each end's largest axis: "
      "%.1f %% within 1, %.1f %% within 2, %.1f %% within 3 (%zu ends)\n",
      100.0 * within(1.0), 100.0 * within(2.0), 100.0 * within(3.0), distance_sigmas.size());
  return 0;
}

}  // namespace cairn::tools
