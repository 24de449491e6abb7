#include "detection/tag_carrier_table.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

TEST(TagCarrierTableTest, ParsesRobotsAndLandmarksAndTurnsTheFaceFrameIntoAprilTags) {
  const auto table = TagCarrierTable::Parse(
      "tags:\n"
      "  - {id: 3, carrier: rover, landmark: false, size: 0.16, position: [0.2, 0.0, 0.8], quaternion: [1, 0, 0, 0]}\n"
      "  - {id: 200, carrier: lander, landmark: true, size: 0.32, position: [0.8, 0, 0.2], quaternion: [1, 0, 0, 0]}\n"
      "  - {id: 201, carrier: lander, landmark: true, size: 0.32, position: [-0.8, 0, 0.2], quaternion: [0, 0, 0, 1]}\n",
      "carriers.yaml");
  ASSERT_TRUE(table.ok()) << table.status().ToString();
  const TagMount* m = table->Find(3);
  ASSERT_NE(m, nullptr);
  EXPECT_EQ(m->carrier, "rover");
  EXPECT_FALSE(m->landmark);
  EXPECT_DOUBLE_EQ(m->size, 0.16);
  // AprilTag's z points into the tag: against the face's outward normal (here the carrier's +z).
  EXPECT_TRUE(m->T_carrier_tag.linear().col(2).isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_TRUE(m->T_carrier_tag.linear().col(1).isApprox(Eigen::Vector3d(0, -1, 0)));
  EXPECT_TRUE(m->T_carrier_tag.translation().isApprox(Eigen::Vector3d(0.2, 0.0, 0.8)));
  EXPECT_EQ(table->Find(4), nullptr);
  EXPECT_EQ(table->Landmarks(), std::vector<std::string>{"lander"});
  EXPECT_EQ(table->LandmarkIndex("lander"), 0);
  EXPECT_EQ(table->LandmarkIndex("rover"), -1);
  EXPECT_EQ(table->Ids(), (std::vector<double>{3, 200, 201}));
}

TEST(TagCarrierTableTest, ErrorsNameTheFileTheLineAndTheKey) {
  const auto unknown = TagCarrierTable::Parse(
      "tags:\n  - {id: 3, carrier: rover, landmark: false, size: 0.16, position: [0, 0, 0], quaternion: [1, 0, 0, 0], "
      "colour: red}\n",
      "carriers.yaml");
  ASSERT_FALSE(unknown.ok());
  EXPECT_NE(unknown.status().message().find("colour"), std::string::npos) << unknown.status().message();
  EXPECT_NE(unknown.status().message().find("carriers.yaml"), std::string::npos);

  const auto missing = TagCarrierTable::Parse("tags:\n  - {id: 3, carrier: rover}\n", "c.yaml");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.status().message().find("size"), std::string::npos) << missing.status().message();

  const auto twice = TagCarrierTable::Parse(
      "tags:\n"
      "  - {id: 3, carrier: rover, landmark: false, size: 0.16, position: [0, 0, 0], quaternion: [1, 0, 0, 0]}\n"
      "  - {id: 3, carrier: hexacopter, landmark: false, size: 0.16, position: [0, 0, 0], quaternion: [1, 0, 0, 0]}\n",
      "c.yaml");
  ASSERT_FALSE(twice.ok());
  EXPECT_NE(twice.status().message().find("twice"), std::string::npos) << twice.status().message();
  EXPECT_NE(twice.status().message().find("line 3"), std::string::npos) << twice.status().message();

  const auto mixed = TagCarrierTable::Parse(
      "tags:\n"
      "  - {id: 3, carrier: lander, landmark: false, size: 0.16, position: [0, 0, 0], quaternion: [1, 0, 0, 0]}\n"
      "  - {id: 4, carrier: lander, landmark: true, size: 0.16, position: [0, 0, 0], quaternion: [1, 0, 0, 0]}\n",
      "c.yaml");
  ASSERT_FALSE(mixed.ok());
  EXPECT_NE(mixed.status().message().find("landmark"), std::string::npos) << mixed.status().message();

  const auto bad_rotation = TagCarrierTable::Parse(
      "tags:\n  - {id: 3, carrier: rover, landmark: false, size: 0.16, position: [0, 0, 0], quaternion: [0.5, 0, 0, 0]}\n",
      "c.yaml");
  ASSERT_FALSE(bad_rotation.ok());
  EXPECT_NE(bad_rotation.status().message().find("unit length"), std::string::npos) << bad_rotation.status().message();

  EXPECT_FALSE(TagCarrierTable::Parse("tags: [", "c.yaml").ok());
  EXPECT_FALSE(TagCarrierTable::Parse("tags: []\n", "c.yaml").ok());
  EXPECT_FALSE(TagCarrierTable::Parse("robots: []\n", "c.yaml").ok());
  const auto absent = TagCarrierTable::Load("/nonexistent/carriers.yaml");
  ASSERT_FALSE(absent.ok());
  EXPECT_NE(absent.status().message().find("/nonexistent/carriers.yaml"), std::string::npos);
}

}  // namespace
}  // namespace cairn
