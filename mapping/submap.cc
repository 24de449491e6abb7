#include "mapping/submap.h"

#include <utility>

#include "common/heap_bytes.h"

namespace cairn {
namespace {

// Every OctoMap tree keeps a 600 KB key buffer for casting rays; a finished submap's tree casts
// none (it is const from here on), and a long mission keeps hundreds of them.
std::unique_ptr<const octomap::OcTree> WithoutRayBuffers(std::unique_ptr<octomap::OcTree> tree) {
  tree->clearKeyRays();
  return tree;
}

// The heap blocks the tree's nodes and children arrays take, which are larger than OctoMap's own
// count of their sizes (memoryUsage()).
size_t TreeHeapBytes(const octomap::OcTree& tree) {
  const size_t nodes = tree.size();
  const size_t inner = nodes - tree.getNumLeafNodes();
  return sizeof(tree) + nodes * HeapBlockBytes(sizeof(octomap::OcTreeNode)) +
         inner * HeapBlockBytes(8 * sizeof(octomap::OcTreeNode*));
}

}  // namespace

Submap::Submap(SubmapMetadata metadata, std::vector<CloudPoint> points, std::unique_ptr<octomap::OcTree> tree,
               SubmapStructure structure)
    : metadata_(std::move(metadata)),
      points_(std::move(points)),
      tree_(WithoutRayBuffers(std::move(tree))),
      tree_bytes_(TreeHeapBytes(*tree_)),
      structure_(std::move(structure)) {}

int64_t Submap::obstacle_points() const {
  int64_t n = 0;
  for (const CloudPoint& p : points_) n += p.obstacle;
  return n;
}

size_t Submap::memory_bytes() const {
  return sizeof(*this) + HeapBytes(points_) + tree_bytes_ + HeapBytes(structure_.viewpoints) +
         HeapBytes(structure_.planes) + HeapBytes(structure_.lines);
}

OpenSubmap::OpenSubmap(const SubmapOptions& options, std::string robot, uint64_t id)
    : cloud_(options.cloud_resolution, 1 << 16), tree_(MakeOccupancyTree(options)) {
  metadata_.robot = std::move(robot);
  metadata_.id = id;
  metadata_.options = options;
}

OccupancyUpdateStats OpenSubmap::Integrate(const CameraPoints& pts, OccupancyIntegrator* integrator) {
  if (metadata_.images == 0) metadata_.start = pts.time;
  metadata_.end = pts.time;
  ++metadata_.images;
  const Eigen::Vector3f view = pts.T_local_cam.translation().cast<float>();
  if (view.allFinite() && (viewpoints_.empty() || (view - viewpoints_.back()).squaredNorm() >=
                                                      kViewpointSpacing * kViewpointSpacing)) {
    viewpoints_.push_back(view);
  }
  cells_.interior.clear();
  cells_.on_face.clear();
  cloud_.AddBatch(pts.p_local, pts.intensity, pts.obstacle, &cells_);
  return integrator->IntegrateCells(pts, cells_, cloud_.inv_resolution(), tree_.get());
}

void OpenSubmap::Restart(uint64_t id) {
  if (tree_->size() > 0) {  // not finished (Finish() leaves both empty)
    cloud_.Clear();
    tree_ = MakeOccupancyTree(metadata_.options);
  }
  viewpoints_.clear();
  SubmapMetadata fresh;
  fresh.robot = std::move(metadata_.robot);
  fresh.id = id;
  fresh.options = metadata_.options;
  metadata_ = std::move(fresh);
}

std::shared_ptr<const Submap> OpenSubmap::Finish(PlaneExtractor* planes, std::vector<SubmapLine> lines) {
  tree_->updateInnerOccupancy();
  tree_->prune();
  SubmapStructure structure;
  std::vector<CloudPoint> points = cloud_.Points();
  if (planes != nullptr) structure.planes = planes->Extract(points, viewpoints_);
  structure.lines = std::move(lines);
  structure.viewpoints = std::move(viewpoints_);
  viewpoints_.clear();
  auto submap =
      std::make_shared<const Submap>(metadata_, std::move(points), std::move(tree_), std::move(structure));
  tree_ = MakeOccupancyTree(metadata_.options);
  cloud_.Clear();
  return submap;
}

}  // namespace cairn
