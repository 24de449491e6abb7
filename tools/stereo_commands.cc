// cairn stereo, cairn stereo-eval and cairn bench stereo: dense matching of one pair, scoring
// against ground truth, and timing our SGM against OpenCV's StereoSGBM side by side.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <time.h>

#include <opencv2/calib3d.hpp>
#include <opencv2/core/utility.hpp>
#include <opencv2/imgproc.hpp>

#include "drivers/replay/euroc_dataset.h"
#include "fpga/fpga_stereo_matcher.h"
#include "fpga/simulated_stereo_device.h"
#include "stereo/bidirectional_raster_matcher.h"
#include "stereo/disparity_evaluator.h"
#include "stereo/opencv_sgbm_matcher.h"
#include "stereo/sgm_matcher.h"
#include "stereo/stereo_image_io.h"
#include "stereo/stereo_rectifier.h"
#include "tools/commands.h"

namespace cairn::tools {
namespace {

// Parses "--key value" pairs and positional arguments; reports unknown keys.
struct ArgMap {
  std::vector<std::string> positional;
  std::vector<std::pair<std::string, std::string>> keys;
  std::vector<std::string> flags;
  std::string error;

  ArgMap(const CommandArgs& args, const std::vector<std::string>& value_keys,
         const std::vector<std::string>& flag_keys) {
    for (size_t i = 0; i < args.args.size(); ++i) {
      const std::string a = args.args[i];
      if (a.rfind("--", 0) != 0) {
        positional.push_back(a);
      } else if (std::find(flag_keys.begin(), flag_keys.end(), a) != flag_keys.end()) {
        flags.push_back(a);
      } else if (std::find(value_keys.begin(), value_keys.end(), a) != value_keys.end()) {
        if (i + 1 >= args.args.size()) {
          error = a + " needs a value";
          return;
        }
        keys.emplace_back(a, args.args[++i]);
      } else {
        error = "unknown option " + a;
        return;
      }
    }
  }
  std::string Get(const std::string& key, const std::string& fallback = "") const {
    for (const auto& [k, v] : keys) {
      if (k == key) return v;
    }
    return fallback;
  }
  bool Has(const std::string& key) const {
    return std::find(flags.begin(), flags.end(), key) != flags.end() || !Get(key).empty();
  }
};

// The matcher's options that ParseSgmOptions reads, taken by `cairn stereo` and `cairn bench stereo` alike.
std::vector<std::string> WithSgmKeys(std::vector<std::string> keys) {
  for (const char* k : {"--max-disparity", "--min-disparity", "--paths", "--threads", "--backend", "--census", "--p1",
                        "--p2", "--uniqueness", "--speckle-size", "--speckle-range", "--lr-max-diff",
                        "--p2-intensity-scale"})
    keys.emplace_back(k);
  return keys;
}

bool ParseInt(const std::string& text, const std::string& what, long* out) {
  char* end = nullptr;
  const long v = std::strtol(text.c_str(), &end, 10);
  if (text.empty() || *end != '\0') {
    std::fprintf(stderr, "cairn: %s must be an integer, got '%s'\n", what.c_str(), text.c_str());
    return false;
  }
  *out = v;
  return true;
}

bool ParseDouble(const std::string& text, const std::string& what, double* out) {
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') {
    std::fprintf(stderr, "cairn: %s must be a number, got '%s'\n", what.c_str(), text.c_str());
    return false;
  }
  *out = v;
  return true;
}

int Fail(const Status& s) {
  std::fprintf(stderr, "cairn: %s\n", s.message().c_str());
  return 1;
}

StereoMatcherInput InputOf(const cv::Mat& l, const cv::Mat& r) {
  StereoMatcherInput in;
  in.left = l.data;
  in.right = r.data;
  in.width = l.cols;
  in.height = l.rows;
  in.stride = static_cast<int>(l.step[0]);
  return in;
}

// Fills the SGM options shared by `stereo` and `bench stereo` from the command line.
bool ParseSgmOptions(const ArgMap& a, SgmOptions* o) {
  long max_d = 0, min_d = 0, paths = 4, threads = 2;
  if (!ParseInt(a.Get("--max-disparity"), "--max-disparity", &max_d)) return false;
  if (!ParseInt(a.Get("--min-disparity", "0"), "--min-disparity", &min_d)) return false;
  // raster4: the FPGA mode's paths (left, up-left, up, up-right), implied by --backend fpga-sim.
  const std::string backend = a.Get("--backend", "simd");
  o->raster_paths = a.Get("--paths") == "raster4" || backend == "fpga-sim";
  if (a.Get("--paths") != "raster4" && !ParseInt(a.Get("--paths", "4"), "--paths", &paths)) {
    return false;
  }
  if (!ParseInt(a.Get("--threads", "2"), "--threads", &threads)) return false;
  if (max_d - min_d < 16 || (max_d - min_d) % 16 != 0 || max_d - min_d > 512) {
    std::fprintf(stderr,
                 "cairn: --max-disparity %ld minus --min-disparity %ld must be a multiple of 16 "
                 "in 16..512\n",
                 max_d, min_d);
    return false;
  }
  if (threads < 1 || threads > 64) {
    std::fprintf(stderr, "cairn: --threads must be in 1..64\n");
    return false;
  }
  o->min_disparity = min_d;
  o->num_disparities = max_d - min_d;
  o->paths = paths;
  o->threads = threads;
  if (backend != "simd" && backend != "scalar" && backend != "fpga-sim") {
    std::fprintf(stderr, "cairn: --backend must be simd, scalar or fpga-sim\n");
    return false;
  }
  o->backend = backend == "simd" ? SgmBackend::kSimd : SgmBackend::kScalar;
  if (a.Has("--fill")) o->fill_holes = true;
  for (const auto& [key, field] : {std::pair<const char*, int64_t*>{"--p1", &o->p1},
                                   {"--p2", &o->p2}, {"--uniqueness", &o->uniqueness_percent},
                                   {"--speckle-size", &o->speckle_max_size},
                                   {"--speckle-range", &o->speckle_max_diff},
                                   {"--lr-max-diff", &o->lr_max_diff},
                                   {"--p2-intensity-scale", &o->p2_intensity_scale}}) {
    if (a.Get(key).empty()) continue;
    long v = 0;
    if (!ParseInt(a.Get(key), key, &v)) return false;
    *field = v;
  }
  const std::string census = a.Get("--census");
  if (!census.empty()) {
    int cw = 0, ch = 0;
    if (std::sscanf(census.c_str(), "%dx%d", &cw, &ch) != 2) {
      std::fprintf(stderr, "cairn: --census must look like 9x7\n");
      return false;
    }
    o->census_width = cw;
    o->census_height = ch;
  }
  const Status s = o->Validate();
  if (!s.ok()) {
    std::fprintf(stderr, "cairn: %s\n", s.message().c_str());
    return false;
  }
  return true;
}

double MedianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? 0.0 : v[v.size() / 2];
}

}  // namespace

int RunStereo(const CommandArgs& args) {
  const char* usage =
      "usage: cairn stereo LEFT RIGHT --max-disparity N [--min-disparity M] [--calib EUROC_DIR] "
      "[--paths 4|8|raster4] --out DISP.pfm [--png VIS.png] [--threads T] "
      "[--backend simd|scalar|fpga-sim] "
      "[--census WxH] [--fill] [--matcher sgm|opencv-3way|opencv-hh4] [--p1 P] [--p2 P] "
      "[--uniqueness PERCENT] [--speckle-size PIXELS] [--speckle-range SIXTEENTHS] "
      "[--lr-max-diff PX] [--p2-intensity-scale GRAY] [--bidirectional]\n";
  if (WantsHelp(args)) return PrintUsage(usage);
  const ArgMap a(args, WithSgmKeys({"--calib", "--out", "--png", "--matcher"}), {"--fill", "--bidirectional"});
  if (!a.error.empty() || a.positional.size() != 2 || a.Get("--out").empty() ||
      a.Get("--max-disparity").empty()) {
    if (!a.error.empty()) std::fprintf(stderr, "cairn: %s\n", a.error.c_str());
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  SgmOptions options;
  if (!ParseSgmOptions(a, &options)) return 2;
  auto pair = LoadGrayPair(a.positional[0], a.positional[1]);
  if (!pair.ok()) return Fail(pair.status());
  StereoMatcherInput input;
  cv::Mat left = pair->left, right = pair->right;
  double focal = 0.0, baseline = 0.0;
  if (!a.Get("--calib").empty()) {
    auto dataset = EurocDataset::Open(a.Get("--calib"));
    if (!dataset.ok()) return Fail(dataset.status().WithContext("--calib"));
    auto rectifier = StereoRectifier::Create(dataset->stereo_calibration());
    if (!rectifier.ok()) return Fail(rectifier.status());
    cv::Mat lr, rr;
    const Status s = rectifier->Rectify(pair->left, pair->right, &lr, &rr);
    if (!s.ok()) return Fail(s);
    left = lr;
    right = rr;
    focal = rectifier->focal_px();
    baseline = rectifier->baseline();
  }
  input = InputOf(left, right);
  input.focal_px = focal;
  input.baseline_m = baseline;
  std::unique_ptr<StereoMatcher> matcher;
  const std::string which = a.Get("--matcher", "sgm");
  if (which == "sgm" && a.Get("--backend") == "fpga-sim") {
    // The cycle-accurate model of the FPGA offload behind the real driver.
    auto fpga = FpgaStereoMatcher::Create(options, std::make_unique<SimulatedStereoDevice>(),
                                          std::chrono::seconds(60));
    if (!fpga.ok()) return Fail(fpga.status());
    matcher = std::move(*fpga);
  } else if (which == "sgm") {
    auto sgm = SgmMatcher::Create(options);
    if (!sgm.ok()) return Fail(sgm.status());
    matcher = std::move(*sgm);
  } else if (which == "opencv-3way" || which == "opencv-hh4") {
    matcher = std::make_unique<OpenCvSgbmMatcher>(
        static_cast<int>(options.min_disparity), static_cast<int>(options.num_disparities),
        which == "opencv-3way" ? cv::StereoSGBM::MODE_SGBM_3WAY : cv::StereoSGBM::MODE_HH4);
  } else {
    std::fprintf(stderr, "cairn: --matcher must be sgm, opencv-3way or opencv-hh4\n");
    return 2;
  }
  // stereo.bidirectional: the raster paths' second, bottom-up pass.
  std::unique_ptr<StereoMatcher> both;
  if (a.Has("--bidirectional")) {
    if (which != "sgm" || !options.raster_paths) {
      std::fprintf(stderr, "cairn: --bidirectional needs the sgm matcher with --paths raster4\n");
      return 2;
    }
    both = std::make_unique<BidirectionalRasterMatcher>(*matcher, 16, options.pixel_error_px);
  }
  StereoMatcherOutput out;
  const Status s = (both != nullptr ? *both : *matcher).Match(input, &out);
  if (!s.ok()) return Fail(s);
  const Status w = WritePfm(a.Get("--out"), DisparityToFloat(out));
  if (!w.ok()) return Fail(w);
  if (!a.Get("--png").empty()) {
    const Status p = WriteDisparityPng(a.Get("--png"), out, static_cast<int>(options.min_disparity),
                                       static_cast<int>(options.min_disparity + options.num_disparities));
    if (!p.ok()) return Fail(p);
  }
  long valid = 0;
  for (int16_t d : out.disparity) valid += d != kInvalidDisparity;
  std::printf("%s: %dx%d, %ld valid pixels (%.1f %%)\n", a.Get("--out").c_str(), out.width,
              out.height, valid, 100.0 * valid / static_cast<double>(out.disparity.size()));
  if (const auto* fpga = dynamic_cast<const FpgaStereoMatcher*>(matcher.get())) {
    std::printf("fpga-sim: %u device cycles\n", fpga->last_frame_cycles());
  }
  return 0;
}

int RunStereoEval(const CommandArgs& args) {
  const char* usage =
      "usage: cairn stereo-eval --est DISP.pfm --gt GT [--gt-scale S] [--mask MASK] "
      "[--metric bad0.5|bad1|bad2|bad3|bad4|d1]\n"
      "  Missing estimates count as bad; the *_interpolated scores first fill them from the background\n"
      "  as KITTI's devkit does.\n";
  if (WantsHelp(args)) return PrintUsage(usage);
  const ArgMap a(args, {"--est", "--gt", "--gt-scale", "--mask", "--metric"}, {});
  if (!a.error.empty() || !a.positional.empty() || a.Get("--est").empty() || a.Get("--gt").empty()) {
    if (!a.error.empty()) std::fprintf(stderr, "cairn: %s\n", a.error.c_str());
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  auto metric = ParseDisparityMetric(a.Get("--metric", "bad1"));
  if (!metric.ok()) return Fail(metric.status());
  double scale = 0.0;
  if (!ParseDouble(a.Get("--gt-scale", "0"), "--gt-scale", &scale)) return 2;
  auto est = ReadPfm(a.Get("--est"));
  if (!est.ok()) return Fail(est.status());
  auto gt = LoadGroundTruth(a.Get("--gt"), scale);
  if (!gt.ok()) return Fail(gt.status());
  FloatImage mask;
  if (!a.Get("--mask").empty()) {
    auto m = LoadMask(a.Get("--mask"));
    if (!m.ok()) return Fail(m.status());
    mask = std::move(*m);
  }
  auto score = DisparityEvaluator::Score(*est, *gt, mask, *metric);
  if (!score.ok()) return Fail(score.status());
  auto filled = DisparityEvaluator::Score(DisparityEvaluator::InterpolateBackground(*est), *gt, mask, *metric);
  if (!filled.ok()) return Fail(filled.status());
  std::printf(
      "{\"metric\": \"%s\", \"bad_nonocc\": %.6f, \"bad_all\": %.6f, \"bad_nonocc_interpolated\": %.6f, "
      "\"bad_all_interpolated\": %.6f, \"bad_estimated\": %.6f, \"density\": %.6f, "
      "\"scored_nonocc\": %ld, \"scored_all\": %ld, \"nonocc_mask\": \"%s\"}\n",
      DisparityMetricName(*metric), score->bad_nonocc, score->bad_all, filled->bad_nonocc, filled->bad_all,
      score->bad_estimated, score->density, score->scored_nonocc, score->scored_all, score->mask_derived ? "derived" : "file");
  return 0;
}

constexpr const char* kBenchStereoUsage =
    "usage: cairn bench stereo [--left L --right R] [--size 1024x508] "
    "[--max-disparity 128] [--paths 4] [--threads 2] [--iterations 15]\n";

int RunBenchStereo(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchStereoUsage);
  const ArgMap a(args, WithSgmKeys({"--left", "--right", "--size", "--iterations"}), {});
  if (!a.error.empty() || !a.positional.empty()) {
    if (!a.error.empty()) std::fprintf(stderr, "cairn: %s\n", a.error.c_str());
    std::fputs(kBenchStereoUsage, stderr);
    return 2;
  }
  const char* env = std::getenv("CAIRN_DATA_DIR");
  const std::string data = env != nullptr ? env : "../shared/data";
  const std::string left_path =
      a.Get("--left", data + "/stereo/middlebury2014q-motorcycle/im0.png");
  const std::string right_path =
      a.Get("--right", data + "/stereo/middlebury2014q-motorcycle/im1.png");
  ArgMap sgm_args = a;
  if (sgm_args.Get("--max-disparity").empty()) sgm_args.keys.emplace_back("--max-disparity", "128");
  SgmOptions options;
  if (!ParseSgmOptions(sgm_args, &options)) return 2;
  int width = 1024, height = 508;
  if (std::sscanf(a.Get("--size", "1024x508").c_str(), "%dx%d", &width, &height) != 2 ||
      width < 16 || height < 16) {
    std::fprintf(stderr, "cairn: --size must look like 1024x508\n");
    return 2;
  }
  long iterations = 15;
  if (!ParseInt(a.Get("--iterations", "15"), "--iterations", &iterations) || iterations < 1) return 2;
  auto pair = LoadGrayPair(left_path, right_path);
  if (!pair.ok()) return Fail(pair.status());
  cv::Mat left, right;
  cv::resize(pair->left, left, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  cv::resize(pair->right, right, cv::Size(width, height), 0, 0, cv::INTER_AREA);
  const StereoMatcherInput input = InputOf(left, right);

  auto sgm = SgmMatcher::Create(options);
  if (!sgm.ok()) return Fail(sgm.status());
  const SgmMatcher* ours_sgm = sgm->get();
  std::vector<SgmMatcher::StageTimes> stages;
  cv::setNumThreads(static_cast<int>(options.threads));
  const int min_d = static_cast<int>(options.min_disparity);
  const int num_d = static_cast<int>(options.num_disparities);
  std::unique_ptr<SgmMatcher> second;  // the bidirectional matcher's inner one; outlives it
  std::vector<std::unique_ptr<StereoMatcher>> matchers;
  matchers.push_back(std::move(*sgm));
  matchers.push_back(std::make_unique<OpenCvSgbmMatcher>(min_d, num_d, cv::StereoSGBM::MODE_SGBM_3WAY));
  matchers.push_back(std::make_unique<OpenCvSgbmMatcher>(min_d, num_d, cv::StereoSGBM::MODE_HH4));
  // The FPGA mode's raster paths also run both ways (stereo.bidirectional) in the daemon profiles.
  if (options.raster_paths) {
    auto inner = SgmMatcher::Create(options);
    if (!inner.ok()) return Fail(inner.status());
    second = std::move(*inner);
    matchers.push_back(std::make_unique<BidirectionalRasterMatcher>(*second, 16, options.pixel_error_px));
  }
  std::vector<std::vector<double>> times(matchers.size()), cpu_times(matchers.size());
  std::vector<StereoMatcherOutput> outputs(matchers.size());
  // Interleaved rounds so that all matchers see the same machine state; one warm-up round.
  for (long it = 0; it <= iterations; ++it) {
    for (size_t m = 0; m < matchers.size(); ++m) {
      const double c0 = ProcessCpuMs();
      const auto t0 = std::chrono::steady_clock::now();
      const Status s = matchers[m]->Match(input, &outputs[m]);
      const auto t1 = std::chrono::steady_clock::now();
      const double c1 = ProcessCpuMs();
      if (!s.ok()) return Fail(s);
      if (it > 0) times[m].push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      if (it > 0) cpu_times[m].push_back(c1 - c0);
      if (it > 0 && m == 0) stages.push_back(ours_sgm->last_stage_times());
    }
  }
  const double ours = MedianMs(times[0]);
  const double ours_cpu = MedianMs(cpu_times[0]);
  std::printf("bench stereo: %dx%d, disparities [%d, %d), %ld paths, %ld threads, %ld iterations, "
              "SIMD target %s\n",
              width, height, min_d, min_d + num_d, static_cast<long>(options.paths),
              static_cast<long>(options.threads), iterations, SimdTargetName());
  std::printf("  (ratio = that matcher's median / %s's median: above 1 means %s is faster)\n",
              std::string(matchers[0]->name()).c_str(), std::string(matchers[0]->name()).c_str());
  for (size_t m = 0; m < matchers.size(); ++m) {
    const double med = MedianMs(times[m]);
    const double cpu = MedianMs(cpu_times[m]);
    long valid = 0;
    for (int16_t d : outputs[m].disparity) valid += d != kInvalidDisparity;
    std::printf("  %-18s wall median %8.2f ms (%6.2f Hz, ratio %.2f)  cpu median %8.2f ms "
                "(ratio %.2f)  density %5.1f %%\n",
                std::string(matchers[m]->name()).c_str(), med, 1000.0 / med, med / ours, cpu,
                cpu / ours_cpu, 100.0 * valid / static_cast<double>(outputs[m].disparity.size()));
  }
  const auto stage_median = [&](double SgmMatcher::StageTimes::*field) {
    std::vector<double> v;
    for (const auto& st : stages) v.push_back(st.*field);
    return MedianMs(v);
  };
  std::printf("  %s stages (median ms): census %.2f, first half %.2f, second half + WTA %.2f, "
              "median %.2f, speckle %.2f, depth %.2f; buffers %.1f MB\n",
              std::string(matchers[0]->name()).c_str(),
              stage_median(&SgmMatcher::StageTimes::census_ms),
              stage_median(&SgmMatcher::StageTimes::first_half_ms),
              stage_median(&SgmMatcher::StageTimes::second_half_ms),
              stage_median(&SgmMatcher::StageTimes::median_ms),
              stage_median(&SgmMatcher::StageTimes::speckle_ms),
              stage_median(&SgmMatcher::StageTimes::depth_ms), ours_sgm->buffer_bytes() / 1e6);
  if (stage_median(&SgmMatcher::StageTimes::row_pass_ms) > 0.0) {
    std::printf("  %s second half on thread 0 (median ms): fused row pass (cost, own vertical and "
                "both horizontal paths, sum, WTA, uniqueness, sub-pixel) %.2f, LR check %.2f\n",
                std::string(matchers[0]->name()).c_str(),
                stage_median(&SgmMatcher::StageTimes::row_pass_ms),
                stage_median(&SgmMatcher::StageTimes::lr_check_ms));
  }
  return 0;
}

}  // namespace cairn::tools
