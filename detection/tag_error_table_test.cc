#include "detection/tag_error_table.h"

#include <cmath>
#include <filesystem>
#include <numbers>
#include <string>

#include <gtest/gtest.h>

#include "common/angles.h"
#include "tests/support/test_data.h"

namespace cairn {
namespace {

// 3 distances (1, 2, 3 m) x 3 angles (0, 30, 60 deg); sigma k of cell (i, j) = (k + 1) * (i + 1) * 0.01 + j * 0.001.
TagErrorTable Grid() {
  TagErrorTable t("rover", 1024, 508, 1080.0, 1080.0, 0.16, 1.0, 3.0, 3, 0.0, 60 * kDegree, 3);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) {
      TagErrorCell& c = t.cell(i, j);
      c.rendered = 10;
      c.detected = 10;
      for (int k = 0; k < 6; ++k) c.sigma[k] = (k + 1) * (i + 1) * 0.01 + j * 0.001;
    }
  return t;
}

TEST(TagErrorTableTest, LooksUpBilinearlyAndScalesWithTheTagSize) {
  const TagErrorTable t = Grid();
  EXPECT_NEAR(t.Sigma(2.0, 30 * kDegree, 0.16)[0], 0.021, 1e-12);
  EXPECT_NEAR(t.Sigma(1.5, 15 * kDegree, 0.16)[1], 2 * 1.5 * 0.01 + 0.0005, 1e-12);
  // Negative angles look like positive ones; beyond the last angle the edge holds.
  EXPECT_NEAR(t.Sigma(2.0, -30 * kDegree, 0.16)[0], 0.021, 1e-12);
  EXPECT_NEAR(t.Sigma(2.0, 85 * kDegree, 0.16)[0], 0.022, 1e-12);
  // A tag twice the size at twice the distance is the same picture, with translations doubled.
  const auto small = t.Sigma(1.0, 0.0, 0.16), big = t.Sigma(2.0, 0.0, 0.32);
  EXPECT_NEAR(big[2], 2.0 * small[2], 1e-12);
  EXPECT_NEAR(big[5], small[5], 1e-12);
  // Beyond the farthest distance: translation grows with the square, rotation linearly.
  const auto edge = t.Sigma(3.0, 0.0, 0.16), beyond = t.Sigma(6.0, 0.0, 0.16);
  EXPECT_NEAR(beyond[0], 4.0 * edge[0], 1e-12);
  EXPECT_NEAR(beyond[3], 2.0 * edge[3], 1e-12);
  // Bad input gives no sigma rather than a wrong one.
  EXPECT_EQ(t.Sigma(std::nan(""), 0.0, 0.16).maxCoeff(), 0.0);
  EXPECT_EQ(t.Sigma(1.0, 0.0, 0.0).maxCoeff(), 0.0);
}

TEST(TagErrorTableTest, SerializesAndParsesBackTheSameTable) {
  TagErrorTable t = Grid();
  t.set_corner_rms(0.12);
  t.set_decimate(1.0);
  const auto back = TagErrorTable::Parse(t.Serialize(), "t.lut");
  ASSERT_TRUE(back.ok()) << back.status().ToString();
  EXPECT_EQ(back->camera(), "rover");
  EXPECT_EQ(back->width(), 1024);
  EXPECT_NEAR(back->corner_rms(), 0.12, 1e-9);
  EXPECT_EQ(back->decimate(), 1.0);
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(back->cell(i, j).sigma[4], t.cell(i, j).sigma[4], 1e-5);
  EXPECT_NEAR(back->Sigma(1.7, 20 * kDegree, 0.2)[3], t.Sigma(1.7, 20 * kDegree, 0.2)[3], 1e-5);
}

TEST(TagErrorTableTest, MalformedFilesNameTheLine) {
  const std::string good = Grid().Serialize();
  const auto error_of = [](const std::string& text) {
    const auto t = TagErrorTable::Parse(text, "x.lut");
    return t.ok() ? std::string("ok") : t.status().message();
  };
  EXPECT_NE(error_of("").find("x.lut: empty"), std::string::npos);
  EXPECT_NE(error_of("hello 1\n").find("x.lut:1: not a tag error table"), std::string::npos);
  EXPECT_NE(error_of("cairn-tag-error-table 3\n").find("version 3"), std::string::npos);
  EXPECT_NE(error_of("cairn-tag-error-table 1\n").find("rebuild it"), std::string::npos);
  // Lines: 1 magic, 2 comment, 3 camera, 4 tag_size, 5 corner_rms, 6 decimate, 7 distances, 8 angles, 9 comment,
  // 10.. rows.
  std::string bad = good;
  bad.replace(bad.find("tag_size 0.16"), 13, "tag_size -1");
  EXPECT_NE(error_of(bad).find("x.lut:4: 'tag_size'"), std::string::npos) << error_of(bad);
  bad = good;
  bad.replace(bad.find("tag_size"), 8, "tag_sise");
  EXPECT_NE(error_of(bad).find("x.lut:4: 'tag_sise' is not a header key"), std::string::npos);
  bad = good;
  bad.replace(bad.find("decimate 2"), 10, "decimate 0.5");
  EXPECT_NE(error_of(bad).find("x.lut:6: 'decimate'"), std::string::npos) << error_of(bad);
  bad = good;
  bad.erase(bad.find("decimate 2"), 11);
  EXPECT_NE(error_of(bad).find("x.lut:9: a row before the header is complete (missing: decimate)"), std::string::npos)
      << error_of(bad);
  // A row short of a number, a NaN, a row out of order, a row missing.
  const size_t row10 = [&] {
    size_t p = 0;
    for (int l = 1; l < 10; ++l) p = good.find('\n', p) + 1;
    return p;
  }();
  const std::string row = good.substr(row10, good.find('\n', row10) - row10);
  bad = good;
  bad.replace(row10, row.size(), row.substr(0, row.rfind(' ')));
  EXPECT_NE(error_of(bad).find("x.lut:10: a row needs 10 numbers"), std::string::npos) << error_of(bad);
  bad = good;
  bad.replace(row10, row.size(), row.substr(0, row.rfind(' ')) + " nan");
  EXPECT_NE(error_of(bad).find("x.lut:10:"), std::string::npos) << error_of(bad);
  bad = good;
  bad.replace(row10, row.size(), "5.0" + row.substr(row.find(' ')));
  EXPECT_NE(error_of(bad).find("x.lut:10: row for distance 5"), std::string::npos) << error_of(bad);
  bad = good.substr(0, good.rfind('\n', good.size() - 2) + 1);
  EXPECT_NE(error_of(bad).find("8 rows where distances x angles is 9"), std::string::npos) << error_of(bad);
  EXPECT_EQ(TagErrorTable::Load("/nonexistent/t.lut").status().code(), StatusCode::kNotFound);
}

TEST(TagErrorTableTest, FillsUndetectedCellsFromTheirNeighboursAndRemovesOutliers) {
  TagErrorTable t("rover", 1024, 508, 1080.0, 1080.0, 0.16, 1.0, 5.0, 5, 0.0, 80 * kDegree, 5);
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      TagErrorCell& c = t.cell(i, j);
      c.rendered = 10;
      // Nothing detected at the farthest distance, nor at the largest angle.
      if (i == 4 || j == 4) continue;
      c.detected = 10;
      c.sigma.setConstant(0.01 * (i + 1));
    }
  t.cell(1, 1).sigma.setConstant(5.0);  // one outlying cell
  t.FillAndSmooth();
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) EXPECT_GT(t.cell(i, j).sigma.minCoeff(), 0.0) << i << "," << j;
  EXPECT_LT(t.cell(1, 1).sigma[0], 0.1);                 // the outlier is gone
  EXPECT_NEAR(t.cell(2, 4).sigma[0], 0.03, 1e-12);       // the angle border's value
  EXPECT_NEAR(t.cell(4, 2).sigma[0], 0.04, 1e-12);       // the last distances' largest
  EXPECT_TRUE(TagErrorTable::Parse(t.Serialize(), "filled").ok());
}

TEST(TagErrorTableTest, EveryShippedTableLoadsAndGrowsWithDistance) {
  int tables = 0;
  for (const auto& e : std::filesystem::directory_iterator(testing::SourceDir() + "/configs/detection")) {
    if (e.path().extension() != ".lut") continue;
    const auto t = TagErrorTable::Load(e.path().string());
    ASSERT_TRUE(t.ok()) << t.status().ToString();
    ++tables;
    // Face on, the depth error of the table's tag grows from the first distance to the last.
    const double near = t->Sigma(t->distance_at(0), 0.0, t->tag_size())[2];
    const double far = t->Sigma(t->distance_at(t->distance_count() - 1), 0.0, t->tag_size())[2];
    EXPECT_GT(far, 5.0 * near) << e.path();
    EXPECT_GT(t->corner_rms(), 0.0) << e.path();
  }
  EXPECT_EQ(tables, 4);  // the rover's and the hexacopter's, for whole-frame scans and region scans
}

}  // namespace
}  // namespace cairn
