#include "daemon/telemetry/estimate_encoder.h"

#include <cstring>

#include "daemon/telemetry/foxglove_fields.h"
#include "foxglove/FrameTransform.pb.h"
#include "foxglove/Grid.pb.h"
#include "foxglove/PointCloud.pb.h"
#include "foxglove/PoseInFrame.pb.h"

namespace cairn {
namespace {

void AddField(const char* name, uint32_t offset, foxglove::NumericType type,
              google::protobuf::RepeatedPtrField<foxglove::PackedElementField>* fields) {
  foxglove::PackedElementField* f = fields->Add();
  f->set_name(name);
  f->set_offset(offset);
  f->set_type(type);
}

}  // namespace

const std::string& EstimateEncoder::Pose(Timestamp time, const Eigen::Isometry3d& T_map_body) {
  foxglove::PoseInFrame m;
  SetFoxgloveTime(time, m.mutable_timestamp());
  m.set_frame_id(kMapFrame);
  SetFoxglovePose(T_map_body, m.mutable_pose());
  m.SerializeToString(&pose_);
  return pose_;
}

const std::string& EstimateEncoder::Transform(Timestamp time, const Eigen::Isometry3d& T_map_body) {
  foxglove::FrameTransform m;
  SetFoxgloveTime(time, m.mutable_timestamp());
  m.set_parent_frame_id(kMapFrame);
  m.set_child_frame_id(kBodyFrame);
  const Eigen::Quaterniond q(T_map_body.linear());
  m.mutable_translation()->set_x(T_map_body.translation().x());
  m.mutable_translation()->set_y(T_map_body.translation().y());
  m.mutable_translation()->set_z(T_map_body.translation().z());
  m.mutable_rotation()->set_x(q.x());
  m.mutable_rotation()->set_y(q.y());
  m.mutable_rotation()->set_z(q.z());
  m.mutable_rotation()->set_w(q.w());
  m.SerializeToString(&transform_);
  return transform_;
}

const std::string& EstimateEncoder::Cloud(Timestamp time, const Eigen::Isometry3d& T_map_submap,
                                          const std::vector<CloudPoint>& points) {
  constexpr uint32_t kStride = 16;  // x y z float32, intensity, obstacle, 2 bytes padding
  foxglove::PointCloud m;
  SetFoxgloveTime(time, m.mutable_timestamp());
  m.set_frame_id(kMapFrame);
  SetFoxglovePose(T_map_submap, m.mutable_pose());
  m.set_point_stride(kStride);
  AddField("x", 0, foxglove::FLOAT32, m.mutable_fields());
  AddField("y", 4, foxglove::FLOAT32, m.mutable_fields());
  AddField("z", 8, foxglove::FLOAT32, m.mutable_fields());
  AddField("intensity", 12, foxglove::UINT8, m.mutable_fields());
  AddField("obstacle", 13, foxglove::UINT8, m.mutable_fields());
  std::string* data = m.mutable_data();
  data->assign(points.size() * kStride, '\0');
  for (size_t i = 0; i < points.size(); ++i) {
    char* p = data->data() + i * kStride;
    std::memcpy(p, points[i].p.data(), 12);  // little-endian float32, as the hosts are
    p[12] = static_cast<char>(points[i].r);
    p[13] = static_cast<char>(points[i].obstacle);
  }
  m.SerializeToString(&cloud_);
  return cloud_;
}

const std::string& EstimateEncoder::Grid(Timestamp time, const Eigen::Isometry3d& T_map_local, double z,
                                         const GridMap& grid) {
  foxglove::Grid m;
  SetFoxgloveTime(time, m.mutable_timestamp());
  m.set_frame_id(kMapFrame);
  // The local frame is gravity aligned, so the grid lies flat in it; cell (0, 0) is its corner.
  SetFoxglovePose(T_map_local * Eigen::Translation3d(grid.origin_x, grid.origin_y, z), m.mutable_pose());
  m.set_column_count(static_cast<uint32_t>(grid.width));
  m.mutable_cell_size()->set_x(grid.resolution);
  m.mutable_cell_size()->set_y(grid.resolution);
  m.set_cell_stride(4);
  m.set_row_stride(static_cast<uint32_t>(grid.width) * 4);
  AddField("traversability", 0, foxglove::FLOAT32, m.mutable_fields());
  m.mutable_data()->assign(reinterpret_cast<const char*>(grid.values.data()), grid.values.size() * sizeof(float));
  m.SerializeToString(&grid_);
  return grid_;
}

}  // namespace cairn
