#include "daemon/pipeline/submap_matching_stage.h"

#include <cmath>
#include <numbers>
#include <sstream>
#include <vector>

#include <gtest/gtest.h>

#include "daemon/pipeline/testing/loop_mission.h"

namespace cairn {
namespace {

using testing::LoopMission;
using testing::MakeLoop;
using testing::OriginError;

class SubmapMatchingStageTest : public ::testing::TestWithParam<ShotFrame> {};

// Both variants close the loop; the 6-DoF one (matching.dof: 6) without gravity.
TEST_P(SubmapMatchingStageTest, ClosesTheLoopAndTheGraphMovesToTheTruth) {
  const LoopMission m = MakeLoop(6);
  GraphStageOptions go;
  go.enabled = true;
  go.pose_every = 1;
  GraphStage graph(go, /*deterministic=*/true);
  GraphStage odometry_only(go, /*deterministic=*/true);
  SubmapMatchingOptions mo;
  mo.enabled = true;
  mo.dof = GetParam();
  SubmapMatchingStage stage(mo, "rover", /*deterministic=*/true, ExecutorOptions{}, nullptr);
  stage.Start();
  for (const GraphInput& in : m.inputs) {
    graph.OnInput(in);
    odometry_only.OnInput(in);
    // As the pipeline does: after the switch into frame n, submap n - 2 is finished.
    if (in.kind == GraphInput::Kind::kFrameSwitch && in.frame_switch.new_frame_id >= 2) {
      stage.OnSubmap(m.submaps[in.frame_switch.new_frame_id - 2]);
      stage.Step(graph);
    }
  }
  stage.OnSubmap(m.submaps[m.submaps.size() - 2]);
  stage.OnSubmap(m.submaps.back());
  stage.Drain(graph);
  graph.Finish();
  odometry_only.Finish();

  const SubmapMatchingReport r = stage.report();
  std::printf("[ matching] %llu submaps (%llu suitable), %llu attempts, %llu matched, %llu accepted; features %.0f ms, "
              "match %.0f ms (median)\n",
              static_cast<unsigned long long>(r.submaps), static_cast<unsigned long long>(r.suitable),
              static_cast<unsigned long long>(r.attempts), static_cast<unsigned long long>(r.matched),
              static_cast<unsigned long long>(r.accepted), r.features_ms_p50, r.match_ms_p50);
  for (const MatchAttempt& a : stage.attempts()) {
    std::printf("[ matching] %llu-%llu: %s; %s\n", static_cast<unsigned long long>(a.a.id),
                static_cast<unsigned long long>(a.b.id), a.result.reason.c_str(), a.verdict.c_str());
  }
  EXPECT_EQ(r.submaps, 6u);
  EXPECT_EQ(r.suitable, 6u);
  ASSERT_GE(r.accepted, 3u);
  for (const MatchAttempt& a : stage.attempts()) {
    EXPECT_NE(a.a.id + 1, a.b.id) << "consecutive submaps are never paired";
    if (!a.result.matched()) continue;
    EXPECT_EQ(a.result.dof, GetParam() == ShotFrame::kFull ? 6 : 4);
    const Eigen::Isometry3d truth = m.T_world_origin[a.a.id].inverse() * m.T_world_origin[a.b.id];
    EXPECT_LT((a.result.T_a_b.translation() - truth.translation()).norm(), 0.05) << a.a.id << "-" << a.b.id;
  }
  const double with = OriginError(graph, m), without = OriginError(odometry_only, m);
  std::printf("[ matching] origin RMSE: %.3f m with loop closures, %.3f m without\n", with, without);
  EXPECT_LT(with, 0.5 * without);

  // matches.csv: a header and one row per attempt, each with the same number of fields.
  std::istringstream csv(stage.FormatCsv());
  std::string line;
  std::getline(csv, line);
  const auto fields = [](const std::string& l) { return std::count(l.begin(), l.end(), ',') + 1; };
  const auto header_fields = fields(line);
  EXPECT_EQ(header_fields, 21);
  size_t rows = 0;
  while (std::getline(csv, line)) {
    EXPECT_EQ(fields(line), header_fields) << line;
    ++rows;
  }
  EXPECT_EQ(rows, stage.attempts().size());
  EXPECT_EQ(graph.report().matches, r.accepted);
}

INSTANTIATE_TEST_SUITE_P(Variants, SubmapMatchingStageTest, ::testing::Values(ShotFrame::kGravity, ShotFrame::kFull),
                         [](const ::testing::TestParamInfo<ShotFrame>& variant) {
                           return std::string(variant.param == ShotFrame::kFull ? "SixDof" : "FourDof");
                         });

}  // namespace
}  // namespace cairn
