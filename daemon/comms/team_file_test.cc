#include "daemon/comms/team_file.h"

#include <gtest/gtest.h>

namespace cairn {
namespace {

const char* kKey = "rq:rM>}U?@Lns47E1%kR.o@n%FcmmsL/@{H8]yf7";

std::string Member(const std::string& name, const std::string& letter, int port) {
  return "  - {name: " + name + ", letter: " + letter + ", address: \"tcp://127.0.0.1:" + std::to_string(port) +
         "\", public_key: \"" + kKey + "\"}\n";
}

TEST(TeamFileTest, ReadsEveryMember) {
  auto f = TeamFile::Parse("members:\n" + Member("rover", "a", 7701) + Member("hexacopter", "b", 7702), "team.yaml");
  ASSERT_TRUE(f.ok()) << f.status().ToString();
  ASSERT_EQ(f->members.size(), 2u);
  EXPECT_EQ(f->Find("hexacopter")->letter, "b");
  EXPECT_EQ(f->FindLetter('a')->name, "rover");
  EXPECT_EQ(f->Find("nobody"), nullptr);
}

TEST(TeamFileTest, NamesTheFileLineAndKeyOfEveryProblem) {
  const std::string text = "members:\n" + Member("rover", "a", 7701) +
                           "  - {name: hexacopter, letter: b, address: \"tcp://127.0.0.1:7702\"}\n" +
                           Member("rover", "c", 7703) + "  - {name: x, letter: A, address: \"udp://h:1\", public_key: \"k\", colour: red}\n";
  auto f = TeamFile::Parse(text, "team.yaml");
  ASSERT_FALSE(f.ok());
  const std::string e = f.status().ToString();
  EXPECT_NE(e.find("members[1]"), std::string::npos) << e;
  EXPECT_NE(e.find("public_key"), std::string::npos) << e;
  EXPECT_NE(e.find("team.yaml:4"), std::string::npos) << e;  // the duplicate name's line
  EXPECT_NE(e.find("'rover' twice"), std::string::npos) << e;
  EXPECT_NE(e.find("colour"), std::string::npos) << e;
}

TEST(TeamFileTest, RefusesBadValues) {
  for (const std::string& bad : {std::string("  - {name: r, letter: ab, address: \"tcp://h:1\", public_key: \"") + kKey + "\"}\n",
                                 std::string("  - {name: r, letter: a, address: \"h:1\", public_key: \"") + kKey + "\"}\n",
                                 std::string("  - {name: \"r o\", letter: a, address: \"tcp://h:1\", public_key: \"") + kKey + "\"}\n",
                                 std::string("  - {name: r, letter: a, address: \"tcp://h:1\", public_key: \"short\"}\n")}) {
    EXPECT_FALSE(TeamFile::Parse("members:\n" + bad, "team.yaml").ok()) << bad;
  }
  EXPECT_FALSE(TeamFile::Parse("members: []\n", "team.yaml").ok());
  EXPECT_FALSE(TeamFile::Parse("robots:\n" + Member("rover", "a", 1), "team.yaml").ok());
  EXPECT_FALSE(TeamFile::Parse("members: [", "team.yaml").ok());
  // A key that is itself a list (a YAML complex key) is refused, not thrown on.
  const auto complex_key = TeamFile::Parse("? [members]\n: 1\n", "team.yaml");
  ASSERT_FALSE(complex_key.ok());
  EXPECT_NE(complex_key.status().message().find("team.yaml:1: unknown key"), std::string::npos)
      << complex_key.status().message();
  EXPECT_FALSE(TeamFile::Load("/nonexistent/team.yaml").ok());
}

}  // namespace
}  // namespace cairn
