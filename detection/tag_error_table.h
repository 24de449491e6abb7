#pragma once
// The precomputed half of thesis 6.2.3's error model: how far a tag's estimated pose lies from the
// truth, by the camera-to-tag distance and the viewing angle, for one camera and tag size. Built
// offline from tags rendered by the simulator's camera model (`cairn detect build-lut`); each cell
// holds the RMS error of each pose coordinate (the tangent of tag_pose_estimator.h: translation in
// the tag's axes, then the rotation vector) over many renderings, the solution nearest the truth
// taken where IPPE's two minima were confused (that ambiguity is the online step's to find).
//
// A tag of another size s is the table's tag (size s0) seen at distance d * s0 / s, with every
// translation scaled by s / s0: one table serves every tag size on one camera. Beyond the table's
// farthest distance the errors grow as they do in a pinhole: translation with the square of the
// distance, rotation linearly.
//
// File (text; '#' starts a comment):
//   cairn-tag-error-table 2
//   camera <name> <width> <height> <fx> <fy>
//   tag_size <m>
//   corner_rms <px>                     the detector's corner error against the truth
//   decimate <f>                        the detector's (tag_detector.h) the table was built with
//   distances <first m> <last m> <count>
//   angles <first deg> <last deg> <count>
//   then count x count rows, distances outer: d angle rendered detected sx sy sz sphi_x sphi_y sphi_z
// Cells where no rendering was detected hold values filled from their neighbours (detected 0).

#include <array>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "common/status.h"

namespace cairn {

struct TagErrorCell {
  int rendered = 0;
  int detected = 0;
  Eigen::Matrix<double, 6, 1> sigma = Eigen::Matrix<double, 6, 1>::Zero();  // m, m, m, rad, rad, rad
};

class TagErrorTable {
 public:
  TagErrorTable() = default;
  // An empty grid of `distances` x `angles` cells (angles in radians), to be filled by a builder.
  TagErrorTable(std::string camera, int width, int height, double fx, double fy, double tag_size,
                double first_distance, double last_distance, int distances, double first_angle,
                double last_angle, int angles);

  // Errors name the file and line.
  static Expected<TagErrorTable> Load(const std::string& path);
  static Expected<TagErrorTable> Parse(const std::string& text, const std::string& source_name);
  std::string Serialize() const;

  // The sigmas for a tag of `tag_size` at `distance` seen at `view_angle` (rad, 0 = face on),
  // bilinear between cells; angles beyond the grid take its edge.
  Eigen::Matrix<double, 6, 1> Sigma(double distance, double view_angle, double tag_size) const;

  // Fills cells without detections, as the thesis does: along each distance, angles beyond the
  // detected ones take the value at the border; then along each angle, distances beyond the
  // detected ones take the largest of the last 10 % detected. Then a 3 x 3 median per coordinate
  // removes single outlying cells.
  void FillAndSmooth();

  bool empty() const { return cells_.empty(); }
  int distance_count() const { return nd_; }
  int angle_count() const { return na_; }
  double distance_at(int i) const { return d0_ + i * Step(d0_, d1_, nd_); }
  double angle_at(int j) const { return a0_ + j * Step(a0_, a1_, na_); }
  TagErrorCell& cell(int i, int j) { return cells_[static_cast<size_t>(i * na_ + j)]; }
  const TagErrorCell& cell(int i, int j) const { return cells_[static_cast<size_t>(i * na_ + j)]; }

  const std::string& camera() const { return camera_; }
  int width() const { return width_; }
  int height() const { return height_; }
  double fx() const { return fx_; }
  double fy() const { return fy_; }
  double tag_size() const { return tag_size_; }
  double corner_rms() const { return corner_rms_; }
  void set_corner_rms(double px) { corner_rms_ = px; }
  // Quads found at full resolution have smaller corner errors than at decimate 2, so a table
  // holds for the one decimation it was built with.
  double decimate() const { return decimate_; }
  void set_decimate(double f) { decimate_ = f; }

 private:
  static double Step(double first, double last, int count) { return count > 1 ? (last - first) / (count - 1) : 0.0; }

  std::string camera_;
  int width_ = 0, height_ = 0;
  double fx_ = 0.0, fy_ = 0.0;
  double tag_size_ = 0.0;
  double corner_rms_ = 0.0;
  double decimate_ = 2.0;
  double d0_ = 0.0, d1_ = 0.0, a0_ = 0.0, a1_ = 0.0;
  int nd_ = 0, na_ = 0;
  std::vector<TagErrorCell> cells_;
};

}  // namespace cairn
