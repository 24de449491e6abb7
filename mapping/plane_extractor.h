#pragma once
// Planar faces of a submap's cloud (paper 003, 3.1; region growing after Weingarten). The cloud is
// cut into cubes; a cube whose points are thin for the stereo error at its range is a planar
// patch. Patches are grown into planes from the flattest one, each neighbour joining while its
// normal and its offset from the plane fitted so far agree. Each plane is the weighted least-squares
// fit of its points, every point weighted by its error along the normal (eq. 5.2, as the nearest
// viewpoint saw it); the fit's covariance is inflated by the residuals' reduced chi-square where the
// points scatter more than the model says. Working from cube moments keeps it to two passes over
// the points. An instance keeps its scratch (one per thread).

#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "mapping/mapping_options.h"
#include "mapping/submap_plane.h"
#include "mapping/voxel_cloud.h"
#include "mapping/voxel_hash_map.h"
#include "stereo/stereo_error_model.h"

namespace cairn {

class PlaneExtractor {
 public:
  PlaneExtractor(const PlaneOptions& options, const StereoErrorModel& error_model);

  struct Stats {
    size_t cubes = 0;  // holding at least min_cell_points
    size_t planar_cubes = 0;
    size_t skipped_points = 0;  // not finite or beyond the key range
  };
  // Planes of `points` (a submap frame), most points first. `viewpoints`: camera centres that saw
  // the cloud, in the same frame; without any, the frame's origin.
  std::vector<SubmapPlane> Extract(std::span<const CloudPoint> points,
                                   std::span<const Eigen::Vector3f> viewpoints, Stats* stats = nullptr);

 private:
  // Moments of points about a reference point near them (float clouds, double sums), each point
  // weighted (w) by its error along the plane's normal.
  struct Moments {
    Eigen::Vector3d ref = Eigen::Vector3d::Zero();
    double w = 0.0, n = 0.0;
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    Eigen::Vector3d unweighted = Eigen::Vector3d::Zero();  // sum
    // Weighted sum of the points' error covariances: what the stereo noise adds to `outer`.
    Eigen::Matrix3d noise = Eigen::Matrix3d::Zero();
    void Add(const Eigen::Vector3d& p, double weight, const Eigen::Matrix3d& error);
    // Another's (unweighted, about its own reference) with one weight and error for all its points.
    void Merge(const Moments& o, double weight, const Eigen::Matrix3d& error);
  };
  struct Fitted {
    Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();
    double offset = 0.0;
    Eigen::Matrix3d information = Eigen::Matrix3d::Zero();  // of (a, b, d), see SubmapPlane
    double chi2 = 0.0;
  };
  // Weighted least-squares plane of the moments, its normal on the side of `hint`. The scatter is
  // corrected by the noise's expected share first: stereo errors lie along the lines of sight, not
  // along the normal, and would tilt the plainly fitted normal towards the cameras by about
  // sigma^2 / extent^2, more than its standard deviation on faces of thousands of points.
  static bool Fit(const Moments& m, const Eigen::Vector3d& hint, Fitted* out);
  struct Cube {
    Moments m;  // about the cube's corner, unweighted
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    Eigen::Vector3d normal = Eigen::Vector3d::Zero();
    Eigen::Vector3d sight = Eigen::Vector3d::Zero();  // unit, from its nearest viewpoint
    double range = 0.0;                               // to that viewpoint, m
    double thickness = 0.0;                           // rms distance of its points from their own plane, m
    double area = 0.0;                                // its points cover, m^2 (exact for a rectangle)
    int region = -1;                                  // -1 none, -2 in a region that was too small
    int plane = -1;  // the plane its points may join: its region's or a neighbour's
    bool planar = false;
  };
  // Error of a point of the cube along `normal` (eq. 5.2 along the line of sight, the pixel error
  // across it).
  double NormalSigma(const Cube& c, const Eigen::Vector3d& normal) const;
  // The whole error covariance of such a point.
  Eigen::Matrix3d PointError(const Cube& c) const;
  double Tolerance(double sigma) const;
  // Cube indices of the 26 neighbours of cube k present in the cloud.
  template <class F>
  void ForEachNeighbour(int k, F&& f) const;
  // Grows region `region` from `seed` into members_; the plane fitted to them.
  Fitted Grow(int seed, int region);

  PlaneOptions options_;
  StereoErrorModel error_model_;
  double cos_max_angle_;
  float inv_cell_;
  VoxelHashMap<int32_t> index_;  // cube key -> cubes_ index
  std::vector<Cube> cubes_;
  std::vector<uint64_t> keys_;  // of each cube
  std::vector<int32_t> point_cube_;
  std::vector<int> order_, queue_, members_;
  std::vector<Moments> plane_moments_;  // per plane, from its points
};

}  // namespace cairn
