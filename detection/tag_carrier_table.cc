#include "detection/tag_carrier_table.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <yaml-cpp/yaml.h>

#include "common/yaml_options_reader.h"

namespace cairn {

Status TagMountOptions::Validate() const {
  if (id != std::floor(id)) return InvalidArgumentError("id must be a whole number");
  if (carrier.empty()) return InvalidArgumentError("carrier must name a robot or a landmark");
  const double n = std::sqrt(quaternion[0] * quaternion[0] + quaternion[1] * quaternion[1] +
                             quaternion[2] * quaternion[2] + quaternion[3] * quaternion[3]);
  if (std::abs(n - 1.0) > 1e-3) return InvalidArgumentError("quaternion must have unit length (it has " + std::to_string(n) + ")");
  return Status::Ok();
}

Expected<TagCarrierTable> TagCarrierTable::Load(const std::string& path) {
  auto text = ReadListFile(path, "tag carrier file");
  if (!text.ok()) return text.status();
  return Parse(*text, path);
}

Expected<TagCarrierTable> TagCarrierTable::Parse(const std::string& text, const std::string& source) {
  auto list = ParseListDocument(text, source, "tags");
  if (!list.ok()) return list.status();
  const YAML::Node tags = *list;
  TagCarrierTable table;
  std::vector<std::string> errors;
  for (size_t i = 0; i < tags.size(); ++i) {
    const std::string where = source + " tags[" + std::to_string(i) + "]";
    const YAML::Node t = tags[i];
    if (!t.IsMap()) {
      errors.push_back(where + ": must be a mapping");
      continue;
    }
    TagMountOptions o;
    YamlOptionsReader reader(t, where);
    if (Status s = reader.Read(o); !s.ok()) {
      errors.push_back(s.message());
      continue;
    }
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.translation() = Eigen::Vector3d(o.position[0], o.position[1], o.position[2]);
    T.linear() = Eigen::Quaterniond(o.quaternion[0], o.quaternion[1], o.quaternion[2], o.quaternion[3])
                     .normalized()
                     .toRotationMatrix();
    if (Status s = table.Add(static_cast<int>(o.id), o.carrier, o.landmark, o.size, T); !s.ok()) {
      errors.push_back(where + " (line " + std::to_string(t.Mark().line + 1) + "): " + s.message());
    }
  }
  if (!errors.empty()) {
    std::string all;
    for (const std::string& e : errors) all += (all.empty() ? "" : "\n") + e;
    return InvalidArgumentError(all);
  }
  return table;
}

Status TagCarrierTable::Add(int id, const std::string& carrier, bool landmark, double size,
                            const Eigen::Isometry3d& T_carrier_face) {
  if (id < 0 || id > 586) return InvalidArgumentError("id " + std::to_string(id) + " is not a tag36h11 id (0..586)");
  if (carrier.empty()) return InvalidArgumentError("tag " + std::to_string(id) + " has no carrier");
  if (!(size > 0.0) || !T_carrier_face.matrix().allFinite())
    return InvalidArgumentError("tag " + std::to_string(id) + ": size and pose must be finite, size positive");
  if (tags_.count(id) != 0) return InvalidArgumentError("tag " + std::to_string(id) + " is listed twice");
  for (const auto& [other, m] : tags_) {
    if (m.carrier == carrier && m.landmark != landmark) {
      return InvalidArgumentError("carrier '" + carrier + "' is a landmark for tag " + std::to_string(landmark ? id : other) +
                                  " but a robot for tag " + std::to_string(landmark ? other : id));
    }
  }
  TagMount m;
  m.id = id;
  m.carrier = carrier;
  m.landmark = landmark;
  m.size = size;
  // Face frame (y up, z out) to AprilTag's (y down, z in): a half turn about x.
  Eigen::Isometry3d T_face_apriltag = Eigen::Isometry3d::Identity();
  T_face_apriltag.linear() = Eigen::Vector3d(1.0, -1.0, -1.0).asDiagonal();
  m.T_carrier_tag = T_carrier_face * T_face_apriltag;
  tags_[id] = m;
  return Status::Ok();
}

const TagMount* TagCarrierTable::Find(int id) const {
  const auto it = tags_.find(id);
  return it == tags_.end() ? nullptr : &it->second;
}

std::vector<double> TagCarrierTable::Ids() const {
  std::vector<double> ids;
  for (const auto& [id, m] : tags_) ids.push_back(id);
  return ids;
}

std::vector<std::string> TagCarrierTable::Landmarks() const {
  std::set<std::string> names;
  for (const auto& [id, m] : tags_) {
    if (m.landmark) names.insert(m.carrier);
  }
  return {names.begin(), names.end()};
}

int TagCarrierTable::LandmarkIndex(const std::string& carrier) const {
  const std::vector<std::string> all = Landmarks();
  const auto it = std::find(all.begin(), all.end(), carrier);
  return it == all.end() ? -1 : static_cast<int>(it - all.begin());
}

}  // namespace cairn
