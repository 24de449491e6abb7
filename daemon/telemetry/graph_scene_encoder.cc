#include "daemon/telemetry/graph_scene_encoder.h"

#include <algorithm>
#include <cmath>
#include <iterator>

#include "daemon/telemetry/estimate_encoder.h"
#include "daemon/telemetry/foxglove_fields.h"
#include "estimation/math/symmetric_eigen.h"
#include "foxglove/SceneUpdate.pb.h"

namespace cairn {
namespace {

constexpr double kMinOriginDiameter = 0.05;  // m
constexpr double kPoseDiameter = 0.03;       // m

void SetColor(double r, double g, double b, double a, foxglove::Color* c) {
  c->set_r(r);
  c->set_g(g);
  c->set_b(b);
  c->set_a(a);
}

// One colour per robot letter, so that a team's graph reads at a glance.
void SetRobotColor(char robot, double alpha, foxglove::Color* c) {
  static constexpr double kPalette[][3] = {{0.95, 0.55, 0.1}, {0.3, 0.8, 0.3}, {0.75, 0.4, 0.95},
                                           {0.95, 0.85, 0.2}, {0.95, 0.35, 0.45}, {0.3, 0.85, 0.85}};
  const auto& rgb = kPalette[static_cast<unsigned char>(robot) % std::size(kPalette)];
  SetColor(rgb[0], rgb[1], rgb[2], alpha, c);
}

void AddPoint(const Eigen::Vector3d& p, foxglove::LinePrimitive* line) {
  foxglove::Point3* q = line->add_points();
  q->set_x(p.x());
  q->set_y(p.y());
  q->set_z(p.z());
}

}  // namespace

const std::string& GraphSceneEncoder::Encode(Timestamp time, char robot, const GraphScene& scene) {
  foxglove::SceneUpdate update;
  foxglove::SceneEntity* e = update.add_entities();
  SetFoxgloveTime(time, e->mutable_timestamp());
  e->set_frame_id(EstimateEncoder::kMapFrame);
  e->set_id(std::string("graph/") + robot);
  foxglove::KeyValuePair* kv = e->add_metadata();
  kv->set_key("origins");
  kv->set_value(std::to_string(scene.origins.size()));
  kv = e->add_metadata();
  kv->set_key("factors");
  kv->set_value(std::to_string(scene.edges.size()));

  std::map<uint64_t, Eigen::Vector3d> position;
  for (const GraphScene::Node& n : scene.origins) {
    position[n.key] = n.T_global.translation();
    foxglove::SpherePrimitive* s = e->add_spheres();
    // The ellipsoid's axes are the covariance's eigenvectors, its diameters 2 x 2 sigma.
    Eigen::Vector3d lambda = Eigen::Vector3d::Zero();
    Eigen::Matrix3d axes = Eigen::Matrix3d::Identity();
    SymmetricEigen(Eigen::Matrix3d(0.5 * (n.position_covariance + n.position_covariance.transpose())), &lambda, &axes);
    if (axes.determinant() < 0.0) axes.col(2) = -axes.col(2);
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.linear() = axes;
    T.translation() = n.T_global.translation();
    SetFoxglovePose(T, s->mutable_pose());
    const Eigen::Vector3d d = (4.0 * lambda.cwiseMax(0.0).cwiseSqrt()).cwiseMax(kMinOriginDiameter);
    s->mutable_size()->set_x(d.x());
    s->mutable_size()->set_y(d.y());
    s->mutable_size()->set_z(d.z());
    SetRobotColor(RobotOfVariable(n.key), 0.6, s->mutable_color());
    foxglove::TextPrimitive* t = e->add_texts();
    Eigen::Isometry3d label = Eigen::Isometry3d::Identity();
    label.translation() = n.T_global.translation() + Eigen::Vector3d(0.0, 0.0, 0.15);
    SetFoxglovePose(label, t->mutable_pose());
    t->set_billboard(true);
    t->set_font_size(14.0);
    t->set_scale_invariant(true);
    SetColor(1.0, 1.0, 1.0, 1.0, t->mutable_color());
    t->set_text(n.label.empty() ? "s" + std::to_string(IndexOfVariable(n.key)) : n.label);
  }
  for (const GraphScene::Node& n : scene.poses) {
    position[n.key] = n.T_global.translation();
    foxglove::SpherePrimitive* s = e->add_spheres();
    SetFoxglovePose(n.T_global, s->mutable_pose());
    s->mutable_size()->set_x(kPoseDiameter);
    s->mutable_size()->set_y(kPoseDiameter);
    s->mutable_size()->set_z(kPoseDiameter);
    SetColor(0.2, 0.7, 1.0, 0.9, s->mutable_color());
  }
  foxglove::LinePrimitive* chain = e->add_lines();  // frame switches (and future matches)
  foxglove::LinePrimitive* legs = e->add_lines();   // origin -> pose
  for (foxglove::LinePrimitive* l : {chain, legs}) {
    l->set_type(foxglove::LinePrimitive::LINE_LIST);
    l->mutable_pose()->mutable_orientation()->set_w(1.0);
    l->set_scale_invariant(true);
  }
  chain->set_thickness(3.0);
  legs->set_thickness(1.0);
  SetColor(0.95, 0.55, 0.1, 1.0, chain->mutable_color());
  SetColor(0.2, 0.7, 1.0, 0.5, legs->mutable_color());
  for (const GraphScene::Edge& edge : scene.edges) {
    const auto a = position.find(edge.from), b = position.find(edge.to);
    if (a == position.end() || b == position.end()) continue;
    foxglove::LinePrimitive* l = edge.kind == FactorKind::kFilterEstimate ? legs : chain;
    AddPoint(a->second, l);
    AddPoint(b->second, l);
  }
  // Every robot's trajectory as this robot's graph places it, in its robot's colour.
  for (const GraphScene::Track& track : scene.tracks) {
    foxglove::SceneEntity* t = update.add_entities();
    SetFoxgloveTime(time, t->mutable_timestamp());
    t->set_frame_id(EstimateEncoder::kMapFrame);
    t->set_id("trajectory/" + track.name);
    foxglove::LinePrimitive* line = t->add_lines();
    line->set_type(foxglove::LinePrimitive::LINE_STRIP);
    line->mutable_pose()->mutable_orientation()->set_w(1.0);
    line->set_scale_invariant(true);
    line->set_thickness(2.0);
    SetRobotColor(track.robot, 1.0, line->mutable_color());
    for (const Eigen::Vector3d& p : track.positions) AddPoint(p, line);
  }
  out_ = update.SerializeAsString();
  return out_;
}

}  // namespace cairn
