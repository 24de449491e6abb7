#include "mapping/plane_extractor.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>
#include <Eigen/LU>

namespace cairn {
namespace {

constexpr double kDegree = 3.14159265358979323846 / 180.0;
// A cube whose points spread less than this along their second axis (a full cube's face gives
// 0.29) holds a line or an edge, not a face: its normal is unreliable.
constexpr double kMinSpread = 0.15;
// A cube filled evenly is 0.29 of its side thick (rms): one thicker than this is no face, however
// noisy the stereo at its range.
constexpr double kMaxThickness = 0.15;
// Floor of a point's error along the normal, so that a viewpoint inside a cube weighs it finitely.
constexpr double kMinSigma = 1e-3;

struct Eigen3 {
  Eigen::Vector3d values;   // ascending
  Eigen::Matrix3d vectors;  // columns
};

Eigen3 Decompose(const Eigen::Matrix3d& m) {
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
  es.computeDirect(m);
  return {es.eigenvalues(), es.eigenvectors()};
}

}  // namespace

void PlaneExtractor::Moments::Add(const Eigen::Vector3d& p, double weight, const Eigen::Matrix3d& error) {
  const Eigen::Vector3d q = p - ref;
  w += weight;
  n += 1.0;
  sum += weight * q;
  outer += weight * q * q.transpose();
  unweighted += q;
  noise += weight * error;
}

void PlaneExtractor::Moments::Merge(const Moments& o, double weight, const Eigen::Matrix3d& error) {
  const Eigen::Vector3d d = o.ref - ref;
  w += weight * o.n;
  n += o.n;
  sum += weight * (o.sum + o.n * d);
  outer += weight * (o.outer + o.sum * d.transpose() + d * o.sum.transpose() + o.n * d * d.transpose());
  unweighted += o.sum + o.n * d;
  noise += weight * o.n * error;
}

PlaneExtractor::PlaneExtractor(const PlaneOptions& options, const StereoErrorModel& error_model)
    : options_(options),
      error_model_(error_model),
      cos_max_angle_(std::cos(options.max_normal_angle * kDegree)),
      inv_cell_(static_cast<float>(1.0 / options.cell_size)),
      index_(4096) {}

double PlaneExtractor::NormalSigma(const Cube& c, const Eigen::Vector3d& normal) const {
  return std::sqrt(std::max(kMinSigma * kMinSigma, normal.dot(PointError(c) * normal)));
}

Eigen::Matrix3d PlaneExtractor::PointError(const Cube& c) const {
  const double along = error_model_.DepthError(c.range);
  const double across = c.range * error_model_.pixel_error_px() / error_model_.focal_px();
  const Eigen::Matrix3d ss = c.sight * c.sight.transpose();
  return along * along * ss + across * across * (Eigen::Matrix3d::Identity() - ss);
}

double PlaneExtractor::Tolerance(double sigma) const {
  return std::max(options_.min_tolerance, options_.tolerance_sigmas * sigma);
}

bool PlaneExtractor::Fit(const Moments& m, const Eigen::Vector3d& hint, Fitted* out) {
  if (!(m.w > 0.0) || m.n < 4.0) return false;
  const Eigen::Vector3d mean = m.sum / m.w;
  Eigen::Vector3d n = Decompose((m.outer - m.noise) / m.w - mean * mean.transpose()).vectors.col(0);
  if (!n.allFinite()) return false;
  if (n.dot(hint) < 0.0) n = -n;
  const double e_ref = -n.dot(mean);  // n . (p - ref) + e_ref is a point's residual
  out->normal = n;
  out->offset = e_ref - n.dot(m.ref);
  out->chi2 = std::max(0.0, n.dot(m.outer * n) + 2.0 * e_ref * n.dot(m.sum) + m.w * e_ref * e_ref);
  // Information of (a, b, d) for residuals n' . p + offset + d, p absolute: rows (u . p, v . p, 1).
  Eigen::Vector3f uf, vf;
  SubmapPlane::Axes(n.cast<float>(), &uf, &vf);
  const Eigen::Vector3d u = uf.cast<double>(), v = vf.cast<double>();
  const Eigen::Vector3d p1 = m.sum + m.w * m.ref;
  const Eigen::Matrix3d p2 =
      m.outer + m.sum * m.ref.transpose() + m.ref * m.sum.transpose() + m.w * m.ref * m.ref.transpose();
  Eigen::Matrix3d& j = out->information;
  j(0, 0) = u.dot(p2 * u);
  j(0, 1) = j(1, 0) = u.dot(p2 * v);
  j(1, 1) = v.dot(p2 * v);
  j(0, 2) = j(2, 0) = u.dot(p1);
  j(1, 2) = j(2, 1) = v.dot(p1);
  j(2, 2) = m.w;
  return true;
}

template <class F>
void PlaneExtractor::ForEachNeighbour(int k, F&& f) const {
  const Eigen::Vector3i key = VoxelKey::Unpack(keys_[static_cast<size_t>(k)]);
  for (int dz = -1; dz <= 1; ++dz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        if (dx == 0 && dy == 0 && dz == 0) continue;
        const Eigen::Vector3i nb = key + Eigen::Vector3i(dx, dy, dz);
        if (!VoxelKey::InRange(nb.x()) || !VoxelKey::InRange(nb.y()) || !VoxelKey::InRange(nb.z())) continue;
        const int32_t* slot = index_.Find(VoxelKey::Pack(nb.x(), nb.y(), nb.z()));
        if (slot != nullptr) f(*slot);
      }
    }
  }
}

PlaneExtractor::Fitted PlaneExtractor::Grow(int seed, int region) {
  members_.assign(1, seed);
  Cube& first = cubes_[static_cast<size_t>(seed)];
  first.region = region;
  Fitted plane;
  plane.normal = first.normal;
  plane.offset = -first.normal.dot(first.mean);
  // Running weighted moments, refitted at every join (3 x 3, cheap).
  Moments grown;
  grown.ref = first.m.ref;
  const auto join = [&](const Cube& c) {
    const double sigma = NormalSigma(c, c.normal);
    grown.Merge(c.m, 1.0 / (sigma * sigma), PointError(c));
  };
  join(first);
  queue_.assign(1, seed);
  for (size_t head = 0; head < queue_.size(); ++head) {
    ForEachNeighbour(queue_[head], [&](int k) {
      Cube& c = cubes_[static_cast<size_t>(k)];
      if (!c.planar || c.region != -1) return;
      if (std::abs(c.normal.dot(plane.normal)) < cos_max_angle_) return;
      // Offsets beyond half a cube are a parallel surface, not noise, at any range.
      const double gate = std::min(0.5 * options_.cell_size, Tolerance(NormalSigma(c, plane.normal)));
      if (std::abs(plane.normal.dot(c.mean) + plane.offset) > gate) return;
      c.region = region;
      members_.push_back(k);
      queue_.push_back(k);
      join(c);
      Fitted refit;
      if (Fit(grown, plane.normal, &refit)) plane = refit;
    });
  }
  return plane;
}

std::vector<SubmapPlane> PlaneExtractor::Extract(std::span<const CloudPoint> points,
                                                 std::span<const Eigen::Vector3f> viewpoints, Stats* stats) {
  Stats local;
  Stats& st = stats != nullptr ? *stats : local;
  st = Stats{};
  index_.Clear();
  cubes_.clear();
  keys_.clear();
  point_cube_.assign(points.size(), -1);
  const double cell = options_.cell_size;
  for (size_t i = 0; i < points.size(); ++i) {
    uint64_t key;
    if (!points[i].p.allFinite() || !VoxelKey::Of(points[i].p, inv_cell_, &key)) {
      ++st.skipped_points;
      continue;
    }
    int32_t& slot = index_[key];
    if (slot == 0) {
      cubes_.emplace_back();
      keys_.push_back(key);
      cubes_.back().m.ref = VoxelKey::Unpack(key).cast<double>() * cell;
      slot = static_cast<int32_t>(cubes_.size());
    }
    point_cube_[i] = slot - 1;
    cubes_[static_cast<size_t>(slot - 1)].m.Add(points[i].p.cast<double>(), 1.0, Eigen::Matrix3d::Zero());
  }
  // The slots held index + 1 (0 marks a new entry); plain indices from here on.
  index_.ForEachMutable([](uint64_t, int32_t& slot) { --slot; });

  const Eigen::Vector3f origin = Eigen::Vector3f::Zero();
  const std::span<const Eigen::Vector3f> views = viewpoints.empty() ? std::span(&origin, 1) : viewpoints;
  Eigen::Vector3d seen = Eigen::Vector3d::Zero();
  for (const Eigen::Vector3f& view : views) seen += view.cast<double>();
  seen /= static_cast<double>(views.size());
  order_.clear();
  for (size_t k = 0; k < cubes_.size(); ++k) {
    Cube& c = cubes_[k];
    const Eigen::Vector3d local_mean = c.m.sum / c.m.n;
    c.mean = c.m.ref + local_mean;
    double best = std::numeric_limits<double>::infinity();
    for (const Eigen::Vector3f& view : views) {
      const Eigen::Vector3d d = c.mean - view.cast<double>();
      if (d.squaredNorm() < best) {
        best = d.squaredNorm();
        c.sight = d;
      }
    }
    c.range = std::sqrt(best);
    c.sight = c.range > 0.0 ? Eigen::Vector3d(c.sight / c.range) : Eigen::Vector3d::UnitZ();
    if (c.m.n < static_cast<double>(options_.min_cell_points)) continue;
    ++st.cubes;
    const Eigen3 e = Decompose(c.m.outer / c.m.n - local_mean * local_mean.transpose());
    c.normal = e.vectors.col(0);
    c.thickness = std::sqrt(std::max(0.0, e.values(0)));
    c.area = 12.0 * std::sqrt(std::max(0.0, e.values(1)) * std::max(0.0, e.values(2)));
    c.planar = c.normal.allFinite() && std::sqrt(std::max(0.0, e.values(1))) >= kMinSpread * cell &&
               c.thickness <= std::min(kMaxThickness * cell, Tolerance(NormalSigma(c, c.normal)));
    if (c.planar) order_.push_back(static_cast<int>(k));
  }
  st.planar_cubes = order_.size();
  // Flattest first (Weingarten): a seed on an edge would start a plane tilted between two faces.
  std::sort(order_.begin(), order_.end(), [&](int a, int b) {
    const Cube &ca = cubes_[static_cast<size_t>(a)], &cb = cubes_[static_cast<size_t>(b)];
    return ca.thickness != cb.thickness ? ca.thickness < cb.thickness : a < b;
  });

  // Regions, each with the plane fitted to its cubes.
  std::vector<Fitted> grown;
  std::vector<double> areas;
  int regions = 0;
  for (const int seed : order_) {
    Cube& s = cubes_[static_cast<size_t>(seed)];
    if (s.region != -1) continue;
    // The cameras' side (Fit keeps the hint's).
    if (s.normal.dot(seen - s.mean) < 0.0) s.normal = -s.normal;
    Fitted f = Grow(seed, regions++);
    double area = 0.0;
    for (const int k : members_) area += cubes_[static_cast<size_t>(k)].area;
    if (area < options_.min_area) {
      for (const int k : members_) cubes_[static_cast<size_t>(k)].region = -2;
      continue;
    }
    for (const int k : members_) cubes_[static_cast<size_t>(k)].plane = static_cast<int>(grown.size());
    grown.push_back(f);
    areas.push_back(area);
  }
  // The points of a plane's cubes and of the cubes around them within tolerance of it: cubes at a
  // face's edges or cut thin by the grid are no patches of their own, yet leaving them out would
  // keep the points on one side of the plane where it crosses from one cube into the next.
  for (size_t k = 0; k < cubes_.size(); ++k) {
    Cube& c = cubes_[k];
    if (c.plane >= 0 || c.region >= 0) continue;
    double best = std::numeric_limits<double>::infinity();
    ForEachNeighbour(static_cast<int>(k), [&](int nb) {
      const Cube& o = cubes_[static_cast<size_t>(nb)];
      if (o.region < 0 || o.plane < 0) return;
      const Fitted& f = grown[static_cast<size_t>(o.plane)];
      const double r = std::abs(f.normal.dot(c.mean) + f.offset);
      if (r < best) {
        best = r;
        c.plane = o.plane;
      }
    });
  }
  plane_moments_.assign(grown.size(), Moments{});
  for (size_t k = 0; k < grown.size(); ++k) plane_moments_[k].ref = -grown[k].offset * grown[k].normal;
  for (size_t i = 0; i < points.size(); ++i) {
    int32_t& at = point_cube_[i];
    if (at < 0) continue;
    const Cube& c = cubes_[static_cast<size_t>(at)];
    at = -1;
    if (c.plane < 0) continue;
    const Fitted& f = grown[static_cast<size_t>(c.plane)];
    const Eigen::Vector3d p = points[i].p.cast<double>();
    const double sigma = NormalSigma(c, f.normal);
    if (std::abs(f.normal.dot(p) + f.offset) > Tolerance(sigma)) continue;
    plane_moments_[static_cast<size_t>(c.plane)].Add(p, 1.0 / (sigma * sigma), PointError(c));
    at = c.plane;  // from here on the point's plane
  }

  // Planes whose fit fails keep points == 0 and are dropped at the end.
  std::vector<SubmapPlane> planes(grown.size());
  for (size_t k = 0; k < grown.size(); ++k) {
    Fitted f;
    if (!Fit(plane_moments_[k], grown[k].normal, &f)) continue;
    const Eigen::FullPivLU<Eigen::Matrix3d> lu(f.information);
    if (!lu.isInvertible()) continue;
    // Points scattering more than the stereo error says (rough or slightly curved faces) widen it.
    const double dof = std::max(1.0, plane_moments_[k].n - 3.0);
    const Eigen::Matrix3d covariance = lu.inverse() * std::max(1.0, f.chi2 / dof);
    if (!covariance.allFinite()) continue;
    SubmapPlane& p = planes[k];
    p.normal = f.normal.cast<float>();
    p.offset = static_cast<float>(f.offset);
    p.covariance = covariance.cast<float>();
    p.points = static_cast<uint32_t>(plane_moments_[k].n);
    p.area = static_cast<float>(areas[k]);
    p.centroid = (plane_moments_[k].ref + plane_moments_[k].unweighted / plane_moments_[k].n).cast<float>();
    p.min = Eigen::Vector2f::Constant(std::numeric_limits<float>::infinity());
    p.max = -p.min;
  }
  // Extents, from the points themselves.
  std::vector<Eigen::Vector3f> us(planes.size()), vs(planes.size());
  for (size_t k = 0; k < planes.size(); ++k) SubmapPlane::Axes(planes[k].normal, &us[k], &vs[k]);
  for (size_t i = 0; i < points.size(); ++i) {
    const int32_t k = point_cube_[i];
    if (k < 0 || planes[static_cast<size_t>(k)].points == 0) continue;
    SubmapPlane& p = planes[static_cast<size_t>(k)];
    const Eigen::Vector3f d = points[i].p - p.centroid;
    const Eigen::Vector2f uv(us[static_cast<size_t>(k)].dot(d), vs[static_cast<size_t>(k)].dot(d));
    p.min = p.min.cwiseMin(uv);
    p.max = p.max.cwiseMax(uv);
  }
  std::erase_if(planes, [](const SubmapPlane& p) { return p.points == 0; });
  std::stable_sort(planes.begin(), planes.end(),
                   [](const SubmapPlane& a, const SubmapPlane& b) { return a.points > b.points; });
  if (planes.size() > static_cast<size_t>(options_.max_planes))
    planes.resize(static_cast<size_t>(options_.max_planes));
  return planes;
}

}  // namespace cairn
