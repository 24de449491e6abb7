#include "mapping/mapping_options.h"

#include <gtest/gtest.h>

#include "common/yaml_options_reader.h"

namespace cairn {
namespace {

constexpr const char* kYaml = R"(
depth: {pixel_error_px: 0.5, min_depth: 0.3, max_depth: 8.0, max_depth_error: 0.2, far_ray_stride_px: 4,
        clear_free_beyond_range: true, max_map_error: 0.1}
fusion: {enabled: true, agreement_sigmas: 2.5, max_images: 8}
obstacles: {edge_jump: 0.2, edge_jump_sigmas: 3.0, max_slope: 0.5, edge_max_gap_rows: 2, edge_max_range: 12.0,
            cell_size: 0.05, window_cells: 4, max_step: 0.1, error_adaptive: true, step_tie_tolerance: 0.01,
            min_cell_points: 3}
rolling_map: {cell_size: 0.05, cells: 400, low_pass: 0.3}
submap: {cloud_resolution: 0.05, octree_resolution: 0.1, log_odds_hit: 0.85, log_odds_miss: -0.4,
         log_odds_min: -2.0, log_odds_max: 3.5, wire_offset_bits: 3,
         wire_intensity_bits: 7}
planes: {enabled: true, cell_size: 0.25, min_cell_points: 12, tolerance_sigmas: 3.0, min_tolerance: 0.02,
         max_normal_angle: 10.0, min_area: 1.0, max_planes: 32}
lines: {enabled: true,
        detection: {min_length_px: 60, max_segments: 200, min_gradient: 5, angle_tolerance_deg: 22.5, max_deviation_px: 1, max_gap_px: 8, max_gap_fraction: 0.25},
        triangulation: {pixel_error_px: 0.5, endpoint_sigma_px: 1, sample_spacing_px: 2, side_offset_px: 2, side_rows: 3, side_row_spacing_px: 1.5, disparity_slope_prior: 0.1, disparity_correlation_px: 5, inlier_sigmas: 3, min_inlier_fraction: 0.7, min_valid_fraction: 0.5, min_support: 12, min_disparity_px: 1, max_depth_sigma: 0.15},
        fusion: {max_angle: 15, gate_chi2: 23.5, max_gap: 0.3, min_sightings: 2, min_length: 0.3, max_lines: 256, max_segments: 32}}
partition: {max_position_sigma: 0.2, max_distance: 7.0, retry_interval: 1.0}
composition: {cloud_resolution: 0.05, rebuild_translation: 0.02, rebuild_rotation_deg: 0.2}
)";

TEST(MappingOptionsTest, LoadsFromYamlAndNamesBadKeys) {
  MappingOptions o;
  YamlOptionsReader reader(YAML::Load(kYaml), "mapping.yaml");
  ASSERT_TRUE(reader.Read(o).ok()) << reader.Read(o).ToString();
  EXPECT_DOUBLE_EQ(o.partition.max_position_sigma, 0.2);
  EXPECT_DOUBLE_EQ(o.planes.cell_size, 0.25);
  EXPECT_TRUE(o.lines.enabled);
  EXPECT_DOUBLE_EQ(o.lines.fusion.gate_chi2, 23.5);
  EXPECT_EQ(o.obstacles.window_cells, 4);
  EXPECT_DOUBLE_EQ(o.obstacles.max_step, 0.1);
  EXPECT_DOUBLE_EQ(o.obstacles.step_tie_tolerance, 0.01);
  EXPECT_EQ(o.obstacles.min_cell_points, 3);
  EXPECT_TRUE(o.fusion.enabled);
  EXPECT_DOUBLE_EQ(o.fusion.agreement_sigmas, 2.5);
  EXPECT_EQ(o.fusion.max_images, 8);
  EXPECT_EQ(o.submap.wire_offset_bits, 3);
  EXPECT_EQ(o.submap.wire_intensity_bits, 7);

  YAML::Node bad = YAML::Load(kYaml);
  bad["obstacles"]["window_cells"] = 9;      // outside 3..6
  bad["partition"]["max_distanse"] = 3.0;    // unknown key
  MappingOptions o2;
  YamlOptionsReader reader2(bad, "mapping.yaml");
  const Status s = reader2.Read(o2);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("obstacles.window_cells"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("partition.max_distanse"), std::string::npos) << s.message();
  EXPECT_NE(s.message().find("mapping.yaml"), std::string::npos) << s.message();
}

}  // namespace
}  // namespace cairn
