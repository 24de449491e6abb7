#pragma once
// Which tag is fixed where: every AprilTag 36h11 id of the team, the robot or landmark (the lander)
// that carries it, its size and its pose on the carrier. Loaded from a YAML file that every robot
// carries (the same on all), or filled by the simulator from its world:
//
//   tags:
//     - {id: 0, carrier: rover, landmark: false, size: 0.16, position: [0.2, 0.0, 0.87],
//        quaternion: [0.0, 0.57, 0.0, 0.82]}
//
// `position` and `quaternion` (w, x, y, z) give the tag's face frame in the carrier's body frame:
// origin at the tag's centre, x to the right and y up as the tag is printed, z out of the face
// (the way a tag is mounted). Poses handed on are in AprilTag's frame (x right, y down, z into
// the tag; see tag_pose_estimator.h), a half turn about x from the face frame.

#include <map>
#include <string>
#include <vector>

#include <Eigen/Geometry>

#include "common/options_visitor.h"
#include "common/status.h"

namespace cairn {

struct TagMountOptions {
  double id = 0;
  std::string carrier;
  bool landmark = false;
  double size = 0.16;
  std::vector<double> position = {0.0, 0.0, 0.0};
  std::vector<double> quaternion = {1.0, 0.0, 0.0, 0.0};

  void Visit(OptionsVisitor& v) {
    v.Number("id", id, 0.0, 586.0, "tag36h11 id");
    v.Text("carrier", carrier);
    v.Flag("landmark", landmark);
    v.Number("size", size, 0.01, 10.0, "m");
    v.Numbers("position", position, 3, 3, -100.0, 100.0, "m");
    v.Numbers("quaternion", quaternion, 4, 4, -1.0, 1.0, "w, x, y, z");
  }
  Status Validate() const;
};

struct TagMount {
  int id = 0;
  std::string carrier;
  bool landmark = false;
  double size = 0.16;
  Eigen::Isometry3d T_carrier_tag = Eigen::Isometry3d::Identity();  // AprilTag's frame
};

class TagCarrierTable {
 public:
  // Errors name the file, the line and the key (a missing, unknown or malformed key, an id twice,
  // a carrier that is a landmark for one tag and a robot for another).
  static Expected<TagCarrierTable> Load(const std::string& path);
  static Expected<TagCarrierTable> Parse(const std::string& text, const std::string& source_name);

  // `T_carrier_face`: the tag's face frame (z out of the face) in the carrier.
  Status Add(int id, const std::string& carrier, bool landmark, double size, const Eigen::Isometry3d& T_carrier_face);

  const TagMount* Find(int id) const;
  const std::map<int, TagMount>& tags() const { return tags_; }
  std::vector<double> Ids() const;
  // Landmark carriers, sorted: a landmark's index here is its graph variable's index (the same on
  // every robot that carries the same table).
  std::vector<std::string> Landmarks() const;
  // Index of `carrier` in Landmarks(), or -1.
  int LandmarkIndex(const std::string& carrier) const;
  bool empty() const { return tags_.empty(); }

 private:
  std::map<int, TagMount> tags_;
};

}  // namespace cairn
