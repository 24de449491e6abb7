#include "mapping/matching/gravity_shot_descriptor.h"

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>
#include <nanoflann.hpp>

#include "estimation/math/symmetric_eigen.h"

namespace cairn {
namespace {

#if NANOFLANN_VERSION >= 0x150
using KdSearchParams = nanoflann::SearchParameters;
#else
using KdSearchParams = nanoflann::SearchParams;
#endif

struct ShotCloudAdaptor {
  const std::vector<Eigen::Vector3f>* points = nullptr;
  size_t kdtree_get_point_count() const { return points->size(); }
  float kdtree_get_pt(uint32_t i, size_t dim) const { return (*points)[i][static_cast<Eigen::Index>(dim)]; }
  template <class BBox>
  bool kdtree_get_bbox(BBox&) const {
    return false;
  }
};

using ShotKdTree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<float, ShotCloudAdaptor>,
                                                   ShotCloudAdaptor, 3, uint32_t>;

// Radius search results into buffers owned by the caller, which stop allocating once grown.
class RadiusCollector {
 public:
  using DistanceType = float;
  using IndexType = uint32_t;
  RadiusCollector(float radius_sq, std::vector<uint32_t>* indices, std::vector<float>* dist_sq)
      : radius_sq_(radius_sq), indices_(indices), dist_sq_(dist_sq) {
    indices_->clear();
    dist_sq_->clear();
  }
  void init() {}
  size_t size() const { return indices_->size(); }
  bool full() const { return true; }
  bool addPoint(float dist_sq, uint32_t index) {
    if (dist_sq < radius_sq_) {
      indices_->push_back(index);
      dist_sq_->push_back(dist_sq);
    }
    return true;
  }
  float worstDist() const { return radius_sq_; }

 private:
  float radius_sq_;
  std::vector<uint32_t>* indices_;
  std::vector<float>* dist_sq_;
};

using Lab = std::array<float, 3>;

// m; within this horizontal distance of the keypoint a point's azimuth (and within this distance
// its elevation) is too noisy to bin: twice the stereo-level noise of the 0.05 m cloud.
constexpr float kAxisBlend = 0.02f;

// sRGB (8 bit) to CIELab under D65.
Lab RgbToLab(uint8_t r8, uint8_t g8, uint8_t b8) {
  static const std::array<float, 256> kLinear = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) {
      const double c = i / 255.0;
      t[static_cast<size_t>(i)] =
          static_cast<float>(c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4));
    }
    return t;
  }();
  const float r = kLinear[r8], g = kLinear[g8], b = kLinear[b8];
  const float x = (0.4124f * r + 0.3576f * g + 0.1805f * b) / 0.95047f;
  const float y = 0.2126f * r + 0.7152f * g + 0.0722f * b;
  const float z = (0.0193f * r + 0.1192f * g + 0.9505f * b) / 1.08883f;
  auto f = [](float t) {
    constexpr float kDelta = 6.0f / 29.0f;
    return t > kDelta * kDelta * kDelta ? std::cbrt(t) : t / (3.0f * kDelta * kDelta) + 4.0f / 29.0f;
  };
  const float fx = f(x), fy = f(y), fz = f(z);
  return {116.0f * fy - 16.0f, 500.0f * (fx - fy), 200.0f * (fy - fz)};
}

// atan2 to within about 1e-5 rad: an odd polynomial for atan on [0, 1] after folding the octants.
// Binning into 45 degree sectors needs far less, and libm's atan2f was a tenth of the descriptor time.
inline float FastAtan2(float y, float x) {
  const float ax = std::abs(x), ay = std::abs(y);
  const float hi = std::max(ax, ay), lo = std::min(ax, ay);
  if (!(hi > 0.0f)) return 0.0f;
  const float t = lo / hi, t2 = t * t;
  float r = t * (0.99997726f +
                 t2 * (-0.33262347f +
                       t2 * (0.19354346f + t2 * (-0.11643287f + t2 * (0.05265332f - 0.01172120f * t2)))));
  if (ay > ax) r = std::numbers::pi_v<float> / 2.0f - r;
  if (x < 0.0f) r = std::numbers::pi_v<float> - r;
  return y < 0.0f ? -r : r;
}

// Linear interpolation between bins whose centres sit at integer positions 0..n-1: the lower bin
// and the weight of the upper one; beyond the outer centres everything goes to the outer bin.
inline void Interpolate(float u, int n, int* lower, float* upper_weight) {
  if (!(u > 0.0f)) {
    *lower = 0;
    *upper_weight = 0.0f;
  } else if (u >= static_cast<float>(n - 1)) {
    *lower = n - 2;
    *upper_weight = 1.0f;
  } else {
    *lower = static_cast<int>(u);
    *upper_weight = u - static_cast<float>(*lower);
  }
}

// Unit eigenvector of the smallest eigenvalue of a symmetric 3x3 matrix, in closed form (the
// eigenvalues by the trigonometric solution of the characteristic cubic, the vector as the largest
// cross product of two rows of A - lambda I): several times faster than an iterative solver, and
// normals are the bulk of the descriptor's work. False when the smallest eigenvalue is not
// separated from the middle one (a line-like neighbourhood has no normal).
bool SmallestEigenvector(const Eigen::Matrix3d& A, Eigen::Vector3f* normal) {
  const double p1 = A(0, 1) * A(0, 1) + A(0, 2) * A(0, 2) + A(1, 2) * A(1, 2);
  const double q = A.trace() / 3.0;
  const double d0 = A(0, 0) - q, d1 = A(1, 1) - q, d2 = A(2, 2) - q;
  const double p = std::sqrt((d0 * d0 + d1 * d1 + d2 * d2 + 2.0 * p1) / 6.0);
  if (!(p > 0.0)) return false;  // isotropic (or empty)
  const Eigen::Matrix3d B = (A - q * Eigen::Matrix3d::Identity()) / p;
  const double r = std::clamp(B.determinant() / 2.0, -1.0, 1.0);
  const double phi = std::acos(r) / 3.0;
  const double largest = q + 2.0 * p * std::cos(phi);
  const double smallest = q + 2.0 * p * std::cos(phi + 2.0 * std::numbers::pi / 3.0);
  const double middle = 3.0 * q - largest - smallest;
  if (middle - smallest <= 1e-9 * (std::abs(largest) + 1e-30)) return false;
  const Eigen::Matrix3d M = A - smallest * Eigen::Matrix3d::Identity();
  const Eigen::Vector3d r0 = M.row(0).transpose(), r1 = M.row(1).transpose(), r2 = M.row(2).transpose();
  const Eigen::Vector3d c0 = r0.cross(r1), c1 = r0.cross(r2), c2 = r1.cross(r2);
  const double n0 = c0.squaredNorm(), n1 = c1.squaredNorm(), n2 = c2.squaredNorm();
  const Eigen::Vector3d& c = n0 >= n1 && n0 >= n2 ? c0 : (n1 >= n2 ? c1 : c2);
  const double len = std::sqrt(std::max({n0, n1, n2}));
  if (!(len > 0.0)) return false;
  *normal = (c / len).cast<float>();
  return true;
}

void NormalizeHalf(float* h, int n) {
  double sum = 0.0;
  for (int i = 0; i < n; ++i) sum += static_cast<double>(h[i]) * h[i];
  if (sum <= 0.0) return;
  const float scale = static_cast<float>(1.0 / std::sqrt(2.0 * sum));
  for (int i = 0; i < n; ++i) h[i] *= scale;
}

}  // namespace

struct GravityShotDescriptor::Impl {
  GravityShotOptions options;
  ShotFrame frame_kind = ShotFrame::kGravity;
  std::vector<Eigen::Vector3f> points;
  std::vector<Lab> lab;
  std::vector<Eigen::Vector3f> normals;
  std::vector<uint8_t> normal_state;  // kUnknown, kValid, kNone
  int64_t non_finite = 0;
  ShotCloudAdaptor adaptor;
  std::unique_ptr<ShotKdTree> tree;
  // Scratch reused by every search.
  std::vector<uint32_t> support, neighbours;
  std::vector<float> support_d2, neighbour_d2, support_d;

  static constexpr uint8_t kUnknown = 0, kValid = 1, kNone = 2;

  void Search(const Eigen::Vector3f& q, double radius, std::vector<uint32_t>* idx,
              std::vector<float>* d2) const {
    RadiusCollector collector(static_cast<float>(radius * radius), idx, d2);
    if (!points.empty()) tree->findNeighbors(collector, q.data(), KdSearchParams{});
  }

  // The normal of point i (oriented toward +z), or null when its neighbourhood is too thin.
  const Eigen::Vector3f* Normal(uint32_t i) {
    if (normal_state[i] == kUnknown) {
      normal_state[i] = kNone;
      Search(points[i], options.normal_radius, &neighbours, &neighbour_d2);
      // Weights 1 - (d / r)^2 fade to 0 at the radius, so a neighbour crossing it by a rounding
      // error (another submap, another yaw) does not turn the normal.
      const double inv_r2 = 1.0 / (options.normal_radius * options.normal_radius);
      double sum_w = 0.0;
      Eigen::Vector3d mean = Eigen::Vector3d::Zero();
      for (size_t m = 0; m < neighbours.size(); ++m) {
        const double w = 1.0 - neighbour_d2[m] * inv_r2;
        sum_w += w;
        mean += w * (points[neighbours[m]] - points[i]).cast<double>();
      }
      // A weighted count: points spread evenly over the disc weigh 1/2 on average.
      if (sum_w >= 0.5 * static_cast<double>(options.min_normal_points)) {
        mean /= sum_w;
        Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
        for (size_t m = 0; m < neighbours.size(); ++m) {
          const double w = 1.0 - neighbour_d2[m] * inv_r2;
          const Eigen::Vector3d e = (points[neighbours[m]] - points[i]).cast<double>() - mean;
          cov.noalias() += w * e * e.transpose();
        }
        Eigen::Vector3f n;
        if (SmallestEigenvector(cov, &n)) {
          if (n.z() < 0.0f) n = -n;
          normals[i] = n;
          normal_state[i] = kValid;
        }
      }
    }
    return normal_state[i] == kValid ? &normals[i] : nullptr;
  }

  bool Compute(const Eigen::Vector3f& k, GravityShot* out, GravityShotFrame* frame);

  // SHOT's frame from the support found last (see the header); false when its scatter has no
  // distinct largest and smallest axes.
  bool FullFrame(const Eigen::Vector3f& k, float radius, Eigen::Matrix3f* axes) const {
    Eigen::Matrix3d scatter = Eigen::Matrix3d::Zero();
    double sum_w = 0.0;
    for (size_t j = 0; j < support.size(); ++j) {
      const Eigen::Vector3d v = (points[support[j]] - k).cast<double>();
      const double w = radius - support_d[j];
      scatter.noalias() += w * v * v.transpose();
      sum_w += w;
    }
    if (!(sum_w > 0.0)) return false;
    Eigen::Vector3d values;
    Eigen::Matrix3d vectors;
    if (!SymmetricEigen(scatter / sum_w, &values, &vectors)) return false;
    if (!(values(2) > values(1) * (1.0 + 1e-6)) || !(values(1) > values(0) * (1.0 + 1e-6))) return false;
    Eigen::Vector3f x = vectors.col(2).cast<float>(), z = vectors.col(0).cast<float>();
    // Each axis points to the side with more support points (ties keep the solver's sign).
    int64_t x_balance = 0, z_balance = 0;
    for (const uint32_t i : support) {
      const Eigen::Vector3f v = points[i] - k;
      x_balance += v.dot(x) >= 0.0f ? 1 : -1;
      z_balance += v.dot(z) >= 0.0f ? 1 : -1;
    }
    if (x_balance < 0) x = -x;
    if (z_balance < 0) z = -z;
    axes->col(0) = x;
    axes->col(1) = z.cross(x);
    axes->col(2) = z;
    return true;
  }
};

bool GravityShotDescriptor::Impl::Compute(const Eigen::Vector3f& k, GravityShot* out,
                                          GravityShotFrame* frame) {
  if (!k.allFinite()) return false;
  const float radius = static_cast<float>(options.support_radius);
  Search(k, radius, &support, &support_d2);
  const size_t n = support.size();
  if (static_cast<int64_t>(n) < options.min_support_points) return false;
  support_d.resize(n);
  for (size_t j = 0; j < n; ++j) support_d[j] = std::sqrt(support_d2[j]);

  // Local frame: x uphill, along the slope of the plane z = a x + b y + c fitted to the support
  // (weights radius - distance). On rock flanks and at the foot of boxes the slope is steep and
  // its direction carries its own sign, which made it far more repeatable between submaps than
  // the principal axis of the horizontal scatter (whose sign must be guessed from the point
  // balance). Centred sums keep the 2x2 normal equations well conditioned.
  double sw = 0.0, mx = 0.0, my = 0.0, mz = 0.0;
  for (size_t j = 0; j < n; ++j) {
    const Eigen::Vector3f v = points[support[j]] - k;
    const double w = radius - support_d[j];
    sw += w;
    mx += w * v.x();
    my += w * v.y();
    mz += w * v.z();
  }
  mx /= sw;
  my /= sw;
  mz /= sw;
  double sxx = 0.0, sxy = 0.0, syy = 0.0, sxz = 0.0, syz = 0.0;
  for (size_t j = 0; j < n; ++j) {
    const Eigen::Vector3f v = points[support[j]] - k;
    const double w = radius - support_d[j];
    const double x = v.x() - mx, y = v.y() - my, z = v.z() - mz;
    sxx += w * x * x;
    sxy += w * x * y;
    syy += w * y * y;
    sxz += w * x * z;
    syz += w * y * z;
  }
  // A support that is a vertical sheet or line has no z(x, y): a small ridge term keeps the
  // solution finite.
  const double ridge = 1e-6 * (sxx + syy) + 1e-12;
  const double axx = sxx + ridge, ayy = syy + ridge;
  const double det = axx * ayy - sxy * sxy;
  const double slope_x = (ayy * sxz - sxy * syz) / det, slope_y = (axx * syz - sxy * sxz) / det;
  const double slope = std::hypot(slope_x, slope_y);
  const double angle = slope > 0.0 && std::isfinite(slope) ? std::atan2(slope_y, slope_x) : 0.0;
  const float cx = static_cast<float>(std::cos(angle)), cy = static_cast<float>(std::sin(angle));
  const bool gravity = frame_kind == ShotFrame::kGravity;
  Eigen::Matrix3f axes;
  axes << cx, -cy, 0.0f, cy, cx, 0.0f, 0.0f, 0.0f, 1.0f;
  if (!gravity && !FullFrame(k, radius, &axes)) return false;

  // Keypoint colour: mean of the points close to it, weighted down to 0 at keypoint_colour_radius,
  // else the nearest point's.
  Lab key_lab{0.0f, 0.0f, 0.0f};
  {
    const float near = static_cast<float>(options.keypoint_colour_radius);
    float sum_w = 0.0f;
    size_t nearest = 0;
    for (size_t j = 0; j < n; ++j) {
      if (support_d[j] < support_d[nearest]) nearest = j;
      if (support_d[j] < near) {
        const float w = 1.0f - support_d[j] / near;
        const Lab& c = lab[support[j]];
        for (size_t i = 0; i < 3; ++i) key_lab[i] += w * c[i];
        sum_w += w;
      }
    }
    if (sum_w > 0.0f) {
      for (float& c : key_lab) c /= sum_w;
    } else {
      key_lab = lab[support[nearest]];
    }
  }

  GravityShot& h = *out;
  h.fill(0.0f);
  float* shape = h.data();
  float* colour = h.data() + kShotVolumes * kShotShapeBins;
  constexpr float kPi = std::numbers::pi_v<float>;
  const float sectors_per_rad = kShotAzimuthBins / (2.0f * kPi);
  const float shells_per_m = static_cast<float>(kShotRadialBins) / radius;
  const float colour_bins_per_unit = static_cast<float>(kShotColourBins / options.colour_range);
  for (size_t j = 0; j < n; ++j) {
    const uint32_t idx = support[j];
    const Eigen::Vector3f v = points[idx] - k;
    const float lx = gravity ? cx * v.x() + cy * v.y() : axes.col(0).dot(v);
    const float ly = gravity ? -cy * v.x() + cx * v.y() : axes.col(1).dot(v);
    const float lz = gravity ? v.z() : axes.col(2).dot(v);
    const float d = support_d[j];
    // Points fade out over the outer kAxisBlend of the sphere, so one crossing its surface by a
    // rounding error changes the descriptor by as little.
    const float rim = std::min(1.0f, (radius - d) / kAxisBlend);

    // Azimuth sectors are circular: the one below and the next, modulo the count. Close to the
    // vertical axis through the keypoint the azimuth is noise (a point on the keypoint itself has
    // none), so there the weight fades into all sectors alike.
    const float rho = std::sqrt(lx * lx + ly * ly);
    const float sharp = std::min(1.0f, rho / kAxisBlend);
    const float ua = (FastAtan2(ly, lx) + kPi) * sectors_per_rad - 0.5f;
    const float fa_floor = std::floor(ua);
    const float wa1 = ua - fa_floor;
    const int a0 = (static_cast<int>(fa_floor) + kShotAzimuthBins) % kShotAzimuthBins;
    int az[kShotAzimuthBins];
    float waz[kShotAzimuthBins];
    int sectors = 2;
    az[0] = a0;
    az[1] = (a0 + 1) % kShotAzimuthBins;
    waz[0] = sharp * (1.0f - wa1);
    waz[1] = sharp * wa1;
    if (sharp < 1.0f) {
      sectors = kShotAzimuthBins;
      for (int a = 0; a < kShotAzimuthBins; ++a) {
        az[a] = a;
        waz[a] = (1.0f - sharp) / kShotAzimuthBins;
      }
      waz[a0] += sharp * (1.0f - wa1);
      waz[(a0 + 1) % kShotAzimuthBins] += sharp * wa1;
    }
    // Elevation by the sine, two halves (both alike at the keypoint); radius, two shells.
    int e0, r0;
    float we1, wr1;
    Interpolate(lz / std::max(d, kAxisBlend) + 0.5f, kShotElevationBins, &e0, &we1);
    Interpolate(d * shells_per_m - 0.5f, kShotRadialBins, &r0, &wr1);

    const Eigen::Vector3f* normal = Normal(idx);
    int s0 = 0;
    float ws1 = 0.0f;
    if (normal != nullptr) {
      const float cosine = gravity ? normal->z() : std::abs(normal->dot(axes.col(2)));
      Interpolate(cosine * kShotShapeBins - 0.5f, kShotShapeBins, &s0, &ws1);
    }
    const Lab& c = lab[idx];
    const float dc = std::abs(c[0] - key_lab[0]) + std::abs(c[1] - key_lab[1]) + std::abs(c[2] - key_lab[2]);
    int c0;
    float wc1;
    Interpolate(dc * colour_bins_per_unit - 0.5f, kShotColourBins, &c0, &wc1);

    const float wel[2] = {1.0f - we1, we1};
    const float wr[2] = {1.0f - wr1, wr1};
    for (int ia = 0; ia < sectors; ++ia) {
      for (int ie = 0; ie < 2; ++ie) {
        const float wae = waz[ia] * wel[ie];
        if (wae == 0.0f) continue;
        for (int ir = 0; ir < 2; ++ir) {
          const float w = wae * wr[ir] * rim;
          if (w == 0.0f) continue;
          const int vol = (az[ia] * kShotElevationBins + e0 + ie) * kShotRadialBins + r0 + ir;
          if (normal != nullptr) {
            float* s = shape + vol * kShotShapeBins + s0;
            s[0] += w * (1.0f - ws1);
            s[1] += w * ws1;
          }
          float* col = colour + vol * kShotColourBins + c0;
          col[0] += w * (1.0f - wc1);
          col[1] += w * wc1;
        }
      }
    }
  }
  NormalizeHalf(shape, kShotVolumes * kShotShapeBins);
  NormalizeHalf(colour, kShotVolumes * kShotColourBins);
  if (frame != nullptr) {
    frame->axes = axes;
    frame->yaw = gravity ? static_cast<float>(angle) : std::atan2(axes(1, 0), axes(0, 0));
    frame->slope = gravity && std::isfinite(slope) ? static_cast<float>(slope) : 0.0f;
    frame->support = static_cast<int32_t>(n);
  }
  return true;
}

GravityShotDescriptor::GravityShotDescriptor(const std::vector<CloudPoint>& cloud,
                                             const GravityShotOptions& options, ShotFrame frame)
    : impl_(std::make_unique<Impl>()) {
  Impl& m = *impl_;
  m.options = options;
  m.frame_kind = frame;
  m.points.reserve(cloud.size());
  m.lab.reserve(cloud.size());
  for (const CloudPoint& c : cloud) {
    if (!c.p.allFinite()) {
      ++m.non_finite;
      continue;
    }
    m.points.push_back(c.p);
    m.lab.push_back(RgbToLab(c.r, c.g, c.b));
  }
  m.normals.resize(m.points.size());
  m.normal_state.assign(m.points.size(), Impl::kUnknown);
  m.adaptor.points = &m.points;
  m.tree = std::make_unique<ShotKdTree>(3, m.adaptor, nanoflann::KDTreeSingleIndexAdaptorParams(16));
}

GravityShotDescriptor::~GravityShotDescriptor() = default;

int64_t GravityShotDescriptor::non_finite_points() const { return impl_->non_finite; }
size_t GravityShotDescriptor::indexed_points() const { return impl_->points.size(); }

bool GravityShotDescriptor::Compute(const Eigen::Vector3f& keypoint, GravityShot* descriptor,
                                    GravityShotFrame* frame) {
  return impl_->Compute(keypoint, descriptor, frame);
}

DescribedKeypoints GravityShotDescriptor::ComputeAll(const std::vector<Eigen::Vector3f>& keypoints) {
  DescribedKeypoints out;
  out.gravity_frames = impl_->frame_kind == ShotFrame::kGravity;
  out.points.reserve(keypoints.size());
  out.descriptors.reserve(keypoints.size());
  out.frames.reserve(keypoints.size());
  out.keypoint_index.reserve(keypoints.size());
  for (size_t i = 0; i < keypoints.size(); ++i) {
    out.descriptors.emplace_back();
    GravityShotFrame frame;
    if (!impl_->Compute(keypoints[i], &out.descriptors.back(), &frame)) {
      out.descriptors.pop_back();
      ++out.dropped;
      continue;
    }
    out.points.push_back(keypoints[i]);
    out.frames.push_back(frame);
    out.keypoint_index.push_back(static_cast<uint32_t>(i));
  }
  return out;
}

float GravityShotDescriptor::Distance(const GravityShot& a, const GravityShot& b) {
  float sum = 0.0f;
  for (int i = 0; i < kGravityShotSize; ++i) {
    const float e = a[static_cast<size_t>(i)] - b[static_cast<size_t>(i)];
    sum += e * e;
  }
  return std::sqrt(sum) / std::numbers::sqrt2_v<float>;
}

}  // namespace cairn
