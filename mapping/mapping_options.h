#pragma once
// Options of the local mapping modules (thesis 5.1, 5.2.2), each with key, unit and range through
// Visit() (common/options_visitor.h). Defaults are the thesis' values where it gives one.

#include <cstdint>
#include <string>

#include "common/options_visitor.h"
#include "mapping/line_options.h"

namespace cairn {

// Depth image to 3-D points, per camera (thesis 5.1.1: drop points whose depth error exceeds a
// per-camera limit; the thesis used 2.5 m to 5 m view distances for about 0.15 m).
struct DepthPointOptions {
  double pixel_error_px = 0.5;   // image coordinate sigma of eq. 5.2
  double min_depth = 0.3;        // m; closer points are the robot itself or mismatches
  double max_depth = 8.0;        // m; hard view-distance limit
  double max_depth_error = 0.15; // m; eq. 5.2c limit, the effective range is the smaller of both
  // Pixels beyond the range only clear free space; one ray per this many pixels in each direction
  // suffices since a 0.1 m voxel at the range limit spans tens of pixels.
  int64_t far_ray_stride_px = 4;
  bool clear_free_beyond_range = true;
  // m; points whose depth error (the fused one with mapping.fusion) exceeds this stay out of the
  // submap's cloud and mark no occupied voxel: their ray only clears free space up to the depth
  // minus that error. Such a point could lie several voxels off, and below a surface seen from
  // above no later ray clears what it marked. The obstacle classifier still sees every point.
  // 0: every point within max_depth_error is mapped (thesis).
  double max_map_error = 0.0;

  void Visit(OptionsVisitor& v) {
    v.Number("pixel_error_px", pixel_error_px, 0.01, 10.0, "px");
    v.Number("min_depth", min_depth, 0.0, 100.0, "m");
    v.Number("max_depth", max_depth, 0.1, 200.0, "m");
    v.Number("max_depth_error", max_depth_error, 0.001, 10.0, "m");
    v.Integer("far_ray_stride_px", far_ray_stride_px, 1, 64, "px");
    v.Flag("clear_free_beyond_range", clear_free_beyond_range);
    v.Number("max_map_error", max_map_error, 0.0, 10.0, "m");
  }
  Status Validate() const {
    if (min_depth >= max_depth) return InvalidArgumentError("min_depth must be below max_depth");
    return Status::Ok();
  }
};

// Temporal fusion of consecutive depth images (per camera): the previous fused depth image is
// warped into each new camera with the filter's relative pose and averaged with the new
// measurement per pixel, weighted by their eq. 5.2c variances, where both agree.
struct DepthFusionOptions {
  bool enabled = false;
  // A pixel fuses when |z_new - z_predicted| <= this many sigmas of their combined eq. 5.2c
  // error; otherwise (occlusion, disocclusion, something moved) the new measurement restarts it.
  double agreement_sigmas = 3.0;
  // The fused variance stays at least the new measurement's over this many images: an average of
  // about the last max_images images, so pose drift and changes of the scene fade out.
  int64_t max_images = 10;

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("agreement_sigmas", agreement_sigmas, 0.5, 20.0, "");
    v.Integer("max_images", max_images, 1, 1000, "images");
  }
};

// Obstacle classification on one depth image (thesis 5.1.1).
struct ObstacleOptions {
  double edge_jump = 0.2;        // m; depth jump between column neighbours that starts a slope test
  // ...plus this many eq. 5.2c depth errors of the near point, so stereo noise between adjacent
  // rows (whose minimal slope is just the ray's declination) does not pass for a cliff.
  double edge_jump_sigmas = 3.0;
  double max_slope = 0.4;        // rise over run the robot can drive (eq. 5.1 threshold, ~22 deg)
  int64_t edge_max_gap_rows = 2; // invalid pixels bridged between column neighbours
  double edge_max_range = 12.0;  // m; the far point of an edge beyond this is placed at it
  double cell_size = 0.05;       // m; 2.5-D height grid
  int64_t window_cells = 5;      // edge of the square window, 3..6 cells
  double max_step = 0.15;        // m; h_max, largest traversable step
  bool error_adaptive = true;    // false: fixed threshold h_max (for comparison)
  // m; cells within this of the window's highest (lowest) cell are tops (feet) of its step as much
  // as that cell is, and eq. 5.4 is taken for each such pair: the step is an obstacle when one pair
  // exceeds h_max + its delta_d. 0: only the two extreme cells (thesis).
  double step_tie_tolerance = 0.02;
  // Cells with fewer points are left out of the height grid (1: every cell, as in the thesis).
  int64_t min_cell_points = 2;

  void Visit(OptionsVisitor& v) {
    v.Number("edge_jump", edge_jump, 0.01, 10.0, "m");
    v.Number("edge_jump_sigmas", edge_jump_sigmas, 0.0, 100.0, "");
    v.Number("max_slope", max_slope, 0.01, 100.0, "");
    v.Integer("edge_max_gap_rows", edge_max_gap_rows, 0, 16, "rows");
    v.Number("edge_max_range", edge_max_range, 0.5, 200.0, "m");
    v.Number("cell_size", cell_size, 0.005, 1.0, "m");
    v.Integer("window_cells", window_cells, 3, 6, "cells");
    v.Number("max_step", max_step, 0.005, 5.0, "m");
    v.Flag("error_adaptive", error_adaptive);
    v.Number("step_tie_tolerance", step_tie_tolerance, 0.0, 0.1, "m");
    v.Integer("min_cell_points", min_cell_points, 1, 10000, "points");
  }
};

// Rolling robot-centred traversability map (thesis 5.1.1, "Local Obstacle Maps").
struct RollingMapOptions {
  double cell_size = 0.05;     // m
  int64_t cells = 400;         // per side (20 m at 0.05 m)
  double low_pass = 0.3;       // weight of a new observation: t = (1 - a) t + a t_new

  void Visit(OptionsVisitor& v) {
    v.Number("cell_size", cell_size, 0.005, 1.0, "m");
    v.Integer("cells", cells, 16, 8192, "cells");
    v.Number("low_pass", low_pass, 0.01, 1.0, "");
  }
};

// Submap representations (thesis 5.1.2).
struct SubmapOptions {
  double cloud_resolution = 0.05;   // m, voxel-centroid filter
  double octree_resolution = 0.1;   // m
  double log_odds_hit = 0.85;
  double log_odds_miss = -0.4;
  double log_odds_min = -2.0;
  double log_odds_max = 3.5;
  // Position of a point inside its voxel on the wire, per axis: 2 bits put it within
  // resolution / 8, far below the stereo scatter of the centroids, and halve the bytes of 4 bits.
  int64_t wire_offset_bits = 2;
  // Intensity or colour on the wire, per channel: 6 bits (steps of 4 grey levels) are below the
  // cameras' noise and take about 2 bits per point less than 8 (exact).
  int64_t wire_intensity_bits = 6;

  void Visit(OptionsVisitor& v) {
    v.Number("cloud_resolution", cloud_resolution, 0.005, 1.0, "m");
    v.Number("octree_resolution", octree_resolution, 0.01, 2.0, "m");
    v.Number("log_odds_hit", log_odds_hit, 0.01, 10.0, "");
    v.Number("log_odds_miss", log_odds_miss, -10.0, -0.01, "");
    v.Number("log_odds_min", log_odds_min, -20.0, -0.01, "");
    v.Number("log_odds_max", log_odds_max, 0.01, 20.0, "");
    v.Integer("wire_offset_bits", wire_offset_bits, 1, 4, "bits per axis");
    v.Integer("wire_intensity_bits", wire_intensity_bits, 1, 8, "bits per channel");
  }
};

// Planar faces of a finished submap (paper 003's region growing from the flattest cell, after
// Weingarten): cells of the cloud that are thin are grown into planes while their normals and
// offsets agree with the plane fitted so far. Tolerances scale with the stereo error (eq. 5.2) of
// each cell as its nearest viewpoint saw it, with a floor for near range.
struct PlaneOptions {
  bool enabled = true;
  double cell_size = 0.3;          // m, side of the cubes planes are grown from
  int64_t min_cell_points = 12;    // cloud points a cube needs to be tested for flatness
  double tolerance_sigmas = 3.0;   // a cube's thickness and offset from the plane, in its error
  double min_tolerance = 0.02;     // m, floor of those tolerances
  double max_normal_angle = 10.0;  // deg between a cube's normal and the plane's
  double min_area = 1.0;           // m^2 of cubes a plane must cover
  int64_t max_planes = 32;         // largest kept per submap

  void Visit(OptionsVisitor& v) {
    v.Flag("enabled", enabled);
    v.Number("cell_size", cell_size, 0.05, 5.0, "m");
    v.Integer("min_cell_points", min_cell_points, 4, 100000, "points");
    v.Number("tolerance_sigmas", tolerance_sigmas, 0.5, 20.0, "sigma");
    v.Number("min_tolerance", min_tolerance, 0.0, 1.0, "m");
    v.Number("max_normal_angle", max_normal_angle, 0.5, 60.0, "deg");
    v.Number("min_area", min_area, 0.01, 10000.0, "m^2");
    v.Integer("max_planes", max_planes, 1, 1000, "planes");
  }
};

// When a new submap starts (thesis 5.1.3).
struct PartitionOptions {
  double max_position_sigma = 0.1;  // m, largest standard deviation of the position
  double max_distance = 7.0;        // m travelled within one submap
  double retry_interval = 1.0;      // s; repeat a request the filter has not acted on

  void Visit(OptionsVisitor& v) {
    v.Number("max_position_sigma", max_position_sigma, 0.001, 100.0, "m");
    v.Number("max_distance", max_distance, 0.1, 10000.0, "m");
    v.Number("retry_interval", retry_interval, 0.01, 3600.0, "s");
  }
};

// Global map composition (thesis 5.2.2).
struct CompositionOptions {
  double cloud_resolution = 0.05;   // m
  // A cached submap contribution is rebuilt when its origin moved by more than this...
  double rebuild_translation = 0.02;  // m
  double rebuild_rotation_deg = 0.2;  // deg

  void Visit(OptionsVisitor& v) {
    v.Number("cloud_resolution", cloud_resolution, 0.005, 1.0, "m");
    v.Number("rebuild_translation", rebuild_translation, 0.0, 10.0, "m");
    v.Number("rebuild_rotation_deg", rebuild_rotation_deg, 0.0, 180.0, "deg");
  }
};

struct MappingOptions {
  DepthPointOptions depth;
  DepthFusionOptions fusion;
  ObstacleOptions obstacles;
  RollingMapOptions rolling_map;
  SubmapOptions submap;
  PlaneOptions planes;
  LineOptions lines;
  PartitionOptions partition;
  CompositionOptions composition;

  void Visit(OptionsVisitor& v) {
    v.Section("depth", depth);
    v.Section("fusion", fusion);
    v.Section("obstacles", obstacles);
    v.Section("rolling_map", rolling_map);
    v.Section("submap", submap);
    v.Section("planes", planes);
    v.Section("lines", lines);
    v.Section("partition", partition);
    v.Section("composition", composition);
  }
};

}  // namespace cairn
