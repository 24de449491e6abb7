// cairn eval --gt GT --est EST [--align se3|4dof|none] [--segments 1,2,5] [--max-dt S]
//   Trajectory accuracy as JSON: ATE after alignment, RPE per segment length, first-to-last drift.
// cairn bench vo [--data DIR] [--repeat N]
//   Visual-odometry time per stereo frame (rectified pairs in memory, no SGM) on an EuRoC/ASL
//   folder: median over frames, split into tracking-only frames and frames that add a keyframe;
//   the same frames in the same runs with the pose from the 3-D alignment alone, as the baseline
//   of the bundle adjustment's cost.

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <vector>

#include "common/json_writer.h"
#include "daemon/pipeline/stereo_rectify_stage.h"
#include "drivers/replay/euroc_dataset.h"
#include "estimation/eval/trajectory_evaluator.h"
#include "estimation/vo/keyframe_visual_odometry.h"
#include "io/image_codec.h"
#include "tools/commands.h"
#include "tools/sample_median.h"

namespace cairn::tools {
namespace {

bool ParseList(const std::string& s, std::vector<double>* out) {
  out->clear();
  std::stringstream ss(s);
  std::string item;
  while (std::getline(ss, item, ',')) {
    char* end = nullptr;
    const double v = std::strtod(item.c_str(), &end);
    if (end == item.c_str() || *end != '\0' || !(v > 0.0)) return false;
    out->push_back(v);
  }
  return !out->empty();
}

Expected<Trajectory> ReadAny(const std::string& path) {
  auto format = TrajectoryIo::FormatFromPath(path);
  if (!format.ok()) return format.status();
  return TrajectoryIo::Read(path, *format);
}

}  // namespace

int RunEval(const CommandArgs& args) {
  const char* usage = "usage: cairn eval --gt GT --est EST [--align se3|4dof|none] [--segments 1,2,5] [--max-dt S]\n";
  if (WantsHelp(args)) return PrintUsage(usage);
  std::string gt_path, est_path, align = "se3";
  TrajectoryEvalOptions o;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--gt" && has_value) gt_path = args.args[++i];
    else if (a == "--est" && has_value) est_path = args.args[++i];
    else if (a == "--align" && has_value) align = args.args[++i];
    else if (a == "--segments" && has_value) {
      if (!ParseList(args.args[++i], &o.segment_lengths)) {
        std::fprintf(stderr, "cairn eval: --segments wants positive lengths in m, e.g. 1,2,5\n");
        return 2;
      }
    } else if (a == "--max-dt" && has_value) {
      o.max_time_difference = std::strtod(args.args[++i], nullptr);
      if (!(o.max_time_difference > 0.0)) {
        std::fprintf(stderr, "cairn eval: --max-dt wants a positive time in s\n");
        return 2;
      }
    } else {
      std::fprintf(stderr, "%s", usage);
      return 2;
    }
  }
  if (gt_path.empty() || est_path.empty()) {
    std::fprintf(stderr, "%s", usage);
    return 2;
  }
  auto alignment = ParseTrajectoryAlignment(align);
  if (!alignment.ok()) {
    std::fprintf(stderr, "cairn eval: %s\n", alignment.status().message().c_str());
    return 2;
  }
  o.alignment = *alignment;
  auto gt = ReadAny(gt_path);
  auto est = ReadAny(est_path);
  for (const auto* t : {&gt, &est}) {
    if (!t->ok()) {
      std::fprintf(stderr, "cairn eval: %s\n", t->status().message().c_str());
      return 1;
    }
  }
  auto r = EvaluateTrajectory(*gt, *est, o);
  if (!r.ok()) {
    std::fprintf(stderr, "cairn eval: %s vs %s: %s\n", est_path.c_str(), gt_path.c_str(), r.status().message().c_str());
    return 1;
  }
  JsonWriter j;
  j.BeginObject();
  j.Field("ground_truth", gt_path).Field("estimate", est_path).Field("alignment", align);
  j.Field("associated_poses", r->associated).Field("duration_s", r->duration).Field("path_length_m", r->path_length);
  j.Key("ate").BeginObject();
  j.Field("rmse_m", r->ate_rmse).Field("mean_m", r->ate_mean).Field("max_m", r->ate_max);
  j.EndObject();
  j.Key("rpe").BeginArray();
  for (const SegmentError& s : r->segments) {
    j.BeginObject();
    j.Field("segment_m", s.length).Field("pairs", s.pairs);
    j.Field("translation_percent", s.translation_percent).Field("rotation_deg_per_m", s.rotation_deg_per_m);
    j.EndObject();
  }
  j.EndArray();
  j.Key("drift").BeginObject();
  j.Field("translation_m", r->drift_translation).Field("rotation_deg", r->drift_rotation_deg);
  j.Field("yaw_deg", r->drift_yaw_deg);
  j.EndObject();
  j.EndObject();
  std::printf("%s\n", j.str().c_str());
  return 0;
}

constexpr const char* kBenchVoUsage =
    "usage: cairn bench vo [--data EUROC_DIR] [--repeat N]\n";

int RunBenchVo(const CommandArgs& args) {
  if (WantsHelp(args)) return PrintUsage(kBenchVoUsage);
  std::string dir = "../shared/data/euroc-v1_01-micro";
  int repeat = 3;
  for (size_t i = 0; i < args.args.size(); ++i) {
    const std::string a = args.args[i];
    const bool has_value = i + 1 < args.args.size();
    if (a == "--data" && has_value) dir = args.args[++i];
    else if (a == "--repeat" && has_value) repeat = std::max(1, std::atoi(args.args[++i]));
    else {
      std::fputs(kBenchVoUsage, stderr);
      return 2;
    }
  }
  auto ds = EurocDataset::Open(dir);
  if (!ds.ok()) {
    std::fprintf(stderr, "cairn bench vo: %s\n", ds.status().message().c_str());
    return 1;
  }
  auto rectify = StereoRectifyStage::Create(ds->stereo_calibration(), 2);
  if (!rectify.ok()) {
    std::fprintf(stderr, "cairn bench vo: %s\n", rectify.status().message().c_str());
    return 1;
  }
  // Load and rectify every pair up front: the timing covers the odometry only.
  std::vector<std::pair<cv::Mat, cv::Mat>> pairs;
  for (const EurocStereoEntry& e : ds->stereo()) {
    auto left = ImageCodec::Read(e.left_path, ImageReadMode::kGray8);
    auto right = ImageCodec::Read(e.right_path, ImageReadMode::kGray8);
    if (!left.ok() || !right.ok()) {
      std::fprintf(stderr, "cairn bench vo: %s\n", (left.ok() ? right : left).status().message().c_str());
      return 1;
    }
    cv::Mat l = std::move(*left);
    cv::Mat r = std::move(*right);
    StereoFrame f;
    const auto image = [](const cv::Mat& m) {
      Image im;
      const size_t n = m.total();
      std::shared_ptr<uint8_t[]> buf(new uint8_t[n]);
      std::copy(m.data, m.data + n, buf.get());
      im.data = buf;
      im.width = m.cols;
      im.height = m.rows;
      im.stride = m.cols;
      return im;
    };
    f.left = image(l);
    f.right = image(r);
    RectifiedPair rp;
    if (!(*rectify)->Rectify(f, &rp)) {
      std::fprintf(stderr, "cairn bench vo: %s: wrong image size for the calibration\n", e.left_path.c_str());
      return 1;
    }
    pairs.emplace_back(cv::Mat(rp.left.height, rp.left.width, CV_8UC1, const_cast<uint8_t*>(rp.left.data.get())).clone(),
                       cv::Mat(rp.right.height, rp.right.width, CV_8UC1, const_cast<uint8_t*>(rp.right.data.get())).clone());
  }
  VoOptions configured, alignment_only;
  alignment_only.bundle_iterations = 0;
  std::vector<double> all, tracking, keyframe, baseline;
  int ok = 0, failed = 0;
  for (int rep = 0; rep < repeat; ++rep) {
    // Alternating the two within each run keeps the machine's drifts out of their ratio.
    for (const bool adjusted : {true, false}) {
      KeyframeVisualOdometry vo(adjusted ? configured : alignment_only, (*rectify)->camera(),
                                (*rectify)->T_body_cam());
      for (size_t i = 0; i < pairs.size(); ++i) {
        const auto t0 = std::chrono::steady_clock::now();
        const VoResult r = vo.Process(ds->stereo()[i].time, pairs[i].first, pairs[i].second);
        const double ms =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
        if (!adjusted) {
          baseline.push_back(ms);
          continue;
        }
        all.push_back(ms);
        (r.new_keyframe ? keyframe : tracking).push_back(ms);
        ok += r.status == VoStatus::kOk ? 1 : 0;
        failed += (r.status != VoStatus::kOk && r.status != VoStatus::kNoKeyframe) ? 1 : 0;
      }
    }
  }
  std::printf("vo on %zu pairs %dx%d x %d runs (rectified in memory, no SGM; %d ok, %d failed)\n", pairs.size(),
              pairs[0].first.cols, pairs[0].first.rows, repeat, ok, failed);
  std::printf("  median %.2f ms per frame (target <= 8 ms)\n", Median(all));
  std::printf("  tracking-only frames: %zu, median %.2f ms\n", tracking.size(), Median(tracking));
  std::printf("  frames adding a keyframe: %zu, median %.2f ms\n", keyframe.size(), Median(keyframe));
  std::printf(
      "  same runs, pose by the 3-D alignment alone (vo.bundle_iterations 0): median %.2f ms; ratio %.3f\n",
      Median(baseline), Median(all) / std::max(Median(baseline), 1e-9));
  return 0;
}

}  // namespace cairn::tools
