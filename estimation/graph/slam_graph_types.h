#pragma once
// Variables and factors of the multi-robot SLAM graph (thesis 4.2), shared by the online graph and
// the background batch solve.

#include <cstdint>

#include "estimation/graph/pose_graph.h"

namespace ceres {
class CostFunction;
}  // namespace ceres

namespace cairn {

// kDatum: T_world_enu, the local east-north-up frame of the team's GNSS datum in the graph's world.
// kPlane: a plane landmark, its frame's x-y plane (plane_factors.h), on a 3-D tangent space.
// kLine: a line landmark, its frame's z axis (line_factors.h), on a 4-D tangent space.
enum class VariableKind : uint8_t {
  kRobotPose = 'x',
  kSubmap = 's',
  kLandmark = 'l',
  kDatum = 'e',
  kPlane = 'p',
  kLine = 'n'
};

// Variable key: robot letter in the top byte (as the g2o multi-robot keys), kind in the next.
constexpr uint64_t VariableKey(VariableKind kind, char robot, uint64_t index) {
  return (static_cast<uint64_t>(static_cast<unsigned char>(robot)) << 56) |
         (static_cast<uint64_t>(kind) << 48) | (index & ((uint64_t{1} << 48) - 1));
}
constexpr VariableKind KindOfKey(uint64_t key) { return static_cast<VariableKind>((key >> 48) & 0xff); }
constexpr char RobotOfVariable(uint64_t key) { return static_cast<char>(key >> 56); }
constexpr uint64_t IndexOfVariable(uint64_t key) { return key & ((uint64_t{1} << 48) - 1); }

enum class FactorKind {
  kPrior,             // unary, own robot's first submap
  kFrameSwitch,       // w: s_i -> s_i+1
  kFilterEstimate,    // v: s_j -> x
  kOdometry,          // u: x_i -> x_i+1 (sequential topology)
  kDetection,         // d: x^r0 -> x^r1
  kLandmark,          // o: x -> l
  kMatch,             // c: s -> s
  kAbsolutePose,      // unary pose fix (known landmark, GNSS with heading)
  kAbsolutePosition,  // unary position fix in the world frame (total station)
  kGnssPosition,      // e -> x: the antenna's position in the datum's east-north-up frame
  kPlaneObservation,  // o: s -> p, a submap's planar face
  kLineObservation,   // o: s -> n, a submap's straight edge
};

struct SlamFactor {
  FactorKind kind = FactorKind::kPrior;
  uint64_t a = 0;     // first (or only) variable
  uint64_t b = 0;     // second variable of binary factors
  Pose3 z;            // measured pose of b in a (binary), of a in the world (unary pose)
  Matrix6d information = Matrix6d::Identity();  // tx ty tz, rotation vector
  Eigen::Vector3d position = Eigen::Vector3d::Zero();               // kAbsolutePosition
  Eigen::Matrix3d position_information = Eigen::Matrix3d::Identity();
  Eigen::Vector3d antenna = Eigen::Vector3d::Zero();  // kGnssPosition: in b's body frame
  // kPlaneObservation: (n, d) of n . p + d = 0 in a's frame, the information of (a, b, d) in its
  // tangent axes; z is the plane's frame in a (where the landmark is placed when it creates it).
  Eigen::Vector4d plane = Eigen::Vector4d(0.0, 0.0, 1.0, 0.0);
  Eigen::Matrix3d plane_information = Eigen::Matrix3d::Identity();
  // kLineObservation: a point (the edge's middle) and the unit direction of the line in a's frame,
  // the information of line_factors.h's error e; z is the line's frame in a.
  Eigen::Vector3d line_point = Eigen::Vector3d::Zero();
  Eigen::Vector3d line_direction = Eigen::Vector3d::UnitZ();
  Eigen::Matrix4d line_information = Eigen::Matrix4d::Identity();
};

bool IsUnary(FactorKind kind);
// Binary factors that measure a relative pose (every one but the GNSS fixes): the edges of the
// pose graph, its chordal initialization and its g2o export.
bool IsPoseEdge(FactorKind kind);
// Factors whose measurement is a position (3 residuals) rather than a pose.
bool IsPositionFactor(FactorKind kind);
// Degrees of freedom of variable `key`: 3 for a plane landmark, 4 for a line, 6 for a pose.
int TangentSizeOf(uint64_t key);
// Structure landmarks (planes, lines): no poses, no vertices of the pose graph.
bool IsStructureVariable(uint64_t key);
bool IsStructureObservation(FactorKind kind);
// Factors that get the Cauchy loss (thesis 4.2.3: detections, landmarks, matches; also fixes).
bool IsRobustFactor(FactorKind kind);

// The g2o / PoseGraph edge of pose-edge factor `f` (with its isotropic SE-Sync weights).
PoseGraphEdge EdgeOfFactor(const SlamFactor& f);

// The residual of `f` (geodesic relative / absolute pose, absolute or GNSS position); caller owns it.
ceres::CostFunction* MakeFactorCostFunction(const SlamFactor& f);

}  // namespace cairn
