#include "sim/terrain.h"

#include <algorithm>
#include <cmath>

#include <gtest/gtest.h>

#include "sim/sim_random.h"

namespace cairn::sim {
namespace {

WorldOptions TerrainWorld() {
  WorldOptions w;
  w.size = 20.0;
  w.seed = 7;
  w.lander.clear();
  return w;
}

// A point of the central 16 m square at z = 0, drawn y first (GCC's argument order), the same on
// every compiler.
Eigen::Vector3d RandomGroundPoint(SimRandom& rng) {
  const double y = rng.Uniform(-8, 8);
  const double x = rng.Uniform(-8, 8);
  return {x, y, 0.0};
}

TEST(TerrainTest, SameSeedSameTerrainOtherSeedOtherTerrain) {
  const Terrain a = Terrain::Generate(TerrainWorld()), b = Terrain::Generate(TerrainWorld());
  WorldOptions o = TerrainWorld();
  o.seed = 8;
  const Terrain c = Terrain::Generate(o);
  int differ = 0;
  for (double x = -9; x < 9; x += 0.37) {
    for (double y = -9; y < 9; y += 0.41) {
      ASSERT_EQ(a.Height(x, y), b.Height(x, y));
      ASSERT_EQ(a.Albedo(x, y), b.Albedo(x, y));
      differ += a.Height(x, y) != c.Height(x, y);
    }
  }
  EXPECT_GT(differ, 100);
}

TEST(TerrainTest, RocksAddSteepStepsToTheGround) {
  WorldOptions smooth = TerrainWorld();
  smooth.rock_density = 0.0;
  smooth.crater_density = 0.0;
  smooth.big_crater = false;
  WorldOptions rocky = smooth;
  rocky.rock_density = 3000.0;
  auto max_slope = [](const Terrain& t) {
    double m = 0.0;
    for (double x = -9.5; x < 9.5; x += 0.05) {
      for (double y = -9.5; y < 9.5; y += 0.05) m = std::max(m, 1.0 / t.Normal(x, y).z());
    }
    return m;
  };
  const double s0 = max_slope(Terrain::Generate(smooth)), s1 = max_slope(Terrain::Generate(rocky));
  EXPECT_LT(s0, 1.5);  // rolling ground: below ~48 deg
  EXPECT_GT(s1, 2.0);  // rock flanks: steeper than 60 deg
}

TEST(TerrainTest, RockSizeScalesTheBoulders) {
  WorldOptions flat = TerrainWorld();
  flat.relief = 0.0;
  flat.crater_density = 0.0;
  flat.big_crater = false;
  flat.rock_density = 2000.0;
  WorldOptions big = flat;
  big.rock_size = 3.0;
  auto highest = [](const Terrain& t) {
    double m = 0.0;
    for (double x = -9.5; x < 9.5; x += 0.05) {
      for (double y = -9.5; y < 9.5; y += 0.05) m = std::max(m, t.Height(x, y));
    }
    return m;
  };
  const double h1 = highest(Terrain::Generate(flat)), h3 = highest(Terrain::Generate(big));
  // The same rocks (same draws), each three times as tall.
  EXPECT_GT(h3, 2.5 * h1);
  EXPECT_LT(h3, 3.5 * h1);
}

// The max-mipmap traversal must return the first intersection: the hit lies on the surface and
// no sample before it along the ray is below the surface.
TEST(TerrainTest, RaycastFindsTheFirstSurfaceHit) {
  const Terrain t = Terrain::Generate(TerrainWorld());
  SimRandom rng(3);
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d o = RandomGroundPoint(rng);
    const Eigen::Vector3d origin(o.x(), o.y(), t.Height(o.x(), o.y()) + rng.Uniform(0.3, 4.0));
    // From grazing (1 deg below the horizon) to steep.
    const double el = -rng.Uniform(0.017, 1.4), az = rng.Uniform(0, 6.283);
    const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const TerrainHit hit = t.Raycast(origin, d, 40.0);
    const double end = hit.t > 0 ? hit.t : 40.0;
    for (double s = 0.0; s < end - 1e-3; s += 0.002) {
      const Eigen::Vector3d p = origin + s * d;
      if (std::abs(p.x()) > 10 || std::abs(p.y()) > 10) break;
      ASSERT_GT(p.z(), t.Height(p.x(), p.y()) - 1e-6) << "ray " << i << " passes below ground at " << s;
    }
    if (hit.t > 0) {
      ++hits;
      const Eigen::Vector3d p = origin + hit.t * d;
      EXPECT_NEAR(p.z(), t.Height(p.x(), p.y()), 1e-6) << "ray " << i;
      EXPECT_NEAR(hit.normal.dot(t.Normal(p.x(), p.y())), 1.0, 1e-3) << "ray " << i;
    }
  }
  EXPECT_GT(hits, 300);
}

// A start distance the ray is clear up to changes nothing about the hit.
TEST(TerrainTest, RaycastFromAClearDistanceFindsTheSameHit) {
  const Terrain t = Terrain::Generate(TerrainWorld());
  SimRandom rng(5);
  int hits = 0;
  for (int i = 0; i < 400; ++i) {
    const Eigen::Vector3d o = RandomGroundPoint(rng);
    const Eigen::Vector3d origin(o.x(), o.y(), t.Height(o.x(), o.y()) + rng.Uniform(0.3, 4.0));
    const double el = -rng.Uniform(0.017, 1.4), az = rng.Uniform(0, 6.283);
    const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const TerrainHit full = t.Raycast(origin, d, 40.0);
    if (full.t <= 0) continue;
    ++hits;
    for (const double f : {0.0, 0.3, 0.9, 0.999}) {
      const TerrainHit from = t.Raycast(origin, d, 40.0, f * full.t);
      ASSERT_NEAR(from.t, full.t, 1e-12 * full.t) << "ray " << i << " from " << f;
      EXPECT_NEAR(from.normal.dot(full.normal), 1.0, 1e-9);
    }
  }
  EXPECT_GT(hits, 300);
}

// Every ray of a bundle (unit directions within `spread` of the central one) is clear of the
// terrain up to the bundle's clear distance, and the distance is not trivially short.
TEST(TerrainTest, ClearDistanceBoundsEveryRayOfTheBundle) {
  const Terrain t = Terrain::Generate(TerrainWorld());
  SimRandom rng(11);
  double gained = 0.0;
  int bundles = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector3d o = RandomGroundPoint(rng);
    const Eigen::Vector3d origin(o.x(), o.y(), t.Height(o.x(), o.y()) + rng.Uniform(0.3, 4.0));
    const double el = -rng.Uniform(0.05, 1.4), az = rng.Uniform(0, 6.283);
    const Eigen::Vector3d d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
    const double spread = rng.Uniform(0.0, 0.02);
    const double clear = t.ClearDistance(origin, d, spread, 40.0);
    ASSERT_GE(clear, 0.0);
    for (int k = 0; k < 20; ++k) {
      // A direction at chord distance <= spread from d (the unit sphere's cap around it).
      const double jz = rng.Uniform(-1, 1), jy = rng.Uniform(-1, 1), jx = rng.Uniform(-1, 1);
      const Eigen::Vector3d jitter(jx, jy, jz);
      Eigen::Vector3d e = (d + 0.5 * spread * jitter).normalized();
      if ((e - d).norm() > spread) e = d;
      const TerrainHit hit = t.Raycast(origin, e, 40.0);
      if (hit.t > 0) {
        ASSERT_GE(hit.t, clear) << "bundle " << i << " ray " << k;
      }
    }
    const TerrainHit centre = t.Raycast(origin, d, 40.0);
    if (centre.t > 0) {
      gained += clear / centre.t;
      ++bundles;
    }
  }
  ASSERT_GT(bundles, 200);
  EXPECT_GT(gained / bundles, 0.5);  // on average the bound reaches more than half way
}

// max_slope bounds the height difference of any two points by their distance.
TEST(TerrainTest, MaxSlopeBoundsTheSurface) {
  const Terrain t = Terrain::Generate(TerrainWorld());
  SimRandom rng(13);
  double steepest = 0.0;
  for (int i = 0; i < 20000; ++i) {
    const double x = rng.Uniform(-9.5, 9.5), y = rng.Uniform(-9.5, 9.5);
    const double a = rng.Uniform(0, 6.283), r = rng.Uniform(0.001, 0.3);
    const double x2 = x + r * std::cos(a), y2 = y + r * std::sin(a);
    const double s = std::abs(t.Height(x2, y2) - t.Height(x, y)) / std::hypot(x2 - x, y2 - y);
    ASSERT_LE(s, t.max_slope());
    steepest = std::max(steepest, s);
  }
  EXPECT_GT(steepest, 0.5 * t.max_slope());
}

TEST(TerrainTest, RaysUpIntoTheSkyMiss) {
  const Terrain t = Terrain::Generate(TerrainWorld());
  EXPECT_LT(t.Raycast({0, 0, t.Height(0, 0) + 1.0}, Eigen::Vector3d(1, 0, 1).normalized(), 100).t, 0.0);
  EXPECT_LT(t.Raycast({50, 0, 5.0}, Eigen::Vector3d(1, 0, -0.1).normalized(), 100).t, 0.0);
}

TEST(TerrainTest, StructuresAreBlocksWithLevelTopsAndSheerSides) {
  WorldOptions w = TerrainWorld();
  // A wall 6 m x 0.4 m, 2 m high, turned 30 deg.
  w.structures = {1.0, -2.0, 30.0, 6.0, 0.4, 2.0};
  ASSERT_TRUE(w.Validate().ok());
  const Terrain plain = Terrain::Generate(TerrainWorld());
  const Terrain t = Terrain::Generate(w);
  const double yaw = 30.0 * M_PI / 180.0;
  const Eigen::Vector2d along(std::cos(yaw), std::sin(yaw)), across(-std::sin(yaw), std::cos(yaw));
  double lowest = 1e9;
  for (double s = -2.9; s <= 2.9; s += 0.05) {
    for (double q = -0.15; q <= 0.15; q += 0.05) {
      const Eigen::Vector2d p = Eigen::Vector2d(1.0, -2.0) + s * along + q * across;
      lowest = std::min(lowest, plain.Height(p.x(), p.y()));
    }
  }
  // Level at 2 m over the lowest ground under it, and lit like the ground from above.
  for (double s : {-2.5, 0.0, 2.5}) {
    const Eigen::Vector2d p = Eigen::Vector2d(1.0, -2.0) + s * along;
    EXPECT_GT(t.Height(p.x(), p.y()), lowest + 1.95);
    EXPECT_LT(t.Height(p.x(), p.y()), lowest + 2.2);
    EXPECT_GT(t.Normal(p.x(), p.y()).z(), 0.999);
  }
  // A level ray towards its side, 1 m up, stops within a grid cell of the side.
  const Eigen::Vector2d foot = Eigen::Vector2d(1.0, -2.0) - 3.0 * across;
  const Eigen::Vector3d origin(foot.x(), foot.y(), lowest + 1.0);
  const TerrainHit hit = t.Raycast(origin, Eigen::Vector3d(across.x(), across.y(), 0.0), 10.0);
  ASSERT_GE(hit.t, 0.0);
  EXPECT_NEAR(hit.t, 2.8, 0.15);
  EXPECT_LT(std::abs(hit.normal.z()), 0.2);
  // Painted: lighter than the regolith between its joints (one runs across its middle).
  const Eigen::Vector2d panel = Eigen::Vector2d(1.0, -2.0) + 0.5 * along;
  EXPECT_GT(t.Albedo(panel.x(), panel.y()), 0.5f);
  EXPECT_LT(t.Albedo(1.0, -2.0), 0.45f);
  // Away from it the ground is unchanged.
  EXPECT_EQ(t.Height(-6.0, 5.0), plain.Height(-6.0, 5.0));
}

TEST(TerrainTest, StructuresOfTheWrongShapeAreRefused) {
  WorldOptions w = TerrainWorld();
  w.structures = {1.0, -2.0, 30.0, 6.0, 0.4};
  EXPECT_NE(w.Validate().message().find("six values per structure"), std::string::npos);
  w.structures = {1.0, -2.0, 30.0, 6.0, 0.4, 0.0};
  EXPECT_NE(w.Validate().message().find("structure 0: height"), std::string::npos);
  w.structures = {9.5, 0.0, 0.0, 4.0, 1.0, 1.0};
  EXPECT_NE(w.Validate().message().find("structure 0: must lie"), std::string::npos);
}

TEST(TerrainTest, TheLanderStandsOnALevelBoulderFreeSite) {
  // Seeds where the default world's lander would stand on a crater wall or among boulders.
  for (int64_t seed : {1, 2, 3}) {
    WorldOptions o;
    o.seed = seed;
    o.rock_density = 3000.0;
    const Terrain t = Terrain::Generate(o);
    const double x = o.lander[0], y = o.lander[1], level = t.Height(x, y);
    double worst = 0.0;
    for (double r = 0.2; r <= o.landing_site - 0.1; r += 0.4) {
      for (double a = 0.0; a < 2 * M_PI; a += 0.3) worst = std::max(worst, std::abs(t.Height(x + r * std::cos(a), y + r * std::sin(a)) - level));
    }
    EXPECT_LT(worst, 1e-4) << "seed " << seed;
    o.landing_site = 0.0;
    const Terrain rough = Terrain::Generate(o);
    double spread = 0.0;
    for (double r = 0.2; r <= 4.9; r += 0.4) {
      for (double a = 0.0; a < 2 * M_PI; a += 0.3) spread = std::max(spread, std::abs(rough.Height(x + r * std::cos(a), y + r * std::sin(a)) - rough.Height(x, y)));
    }
    EXPECT_GT(spread, 0.05) << "seed " << seed << ": without a site the ground there is not level";
  }
}

}  // namespace
}  // namespace cairn::sim
