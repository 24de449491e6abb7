#include "common/yaml_options_reader.h"

#include <unistd.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include "common/options_yaml_writer.h"

namespace cairn {
namespace {

enum class Mode { kA, kB };

struct Inner {
  double gain = 1.0;
  std::vector<double> xy = {0, 0};
  void Visit(OptionsVisitor& v) {
    v.Number("gain", gain, 0.0, 10.0, "1/s");
    v.Numbers("xy", xy, 2, 2, -5.0, 5.0, "m");
  }
  Status Validate() const {
    return xy[0] <= xy[1] ? Status::Ok() : InvalidArgumentError("xy must be ascending");
  }
};

struct Outer {
  int depth = 4;
  bool on = false;
  std::string name;
  Mode mode = Mode::kA;
  Inner inner;
  void Visit(OptionsVisitor& v) {
    v.Integer("depth", depth, 1, 16, "items");
    v.Flag("on", on);
    v.Text("name", name);
    v.Choice("mode", mode, {{"a", Mode::kA}, {"b", Mode::kB}});
    v.Section("inner", inner);
  }
};

Status Read(const std::string& text, Outer* out, std::set<std::string> overridden = {}) {
  YamlOptionsReader r(YAML::Load(text), "test.yaml", std::move(overridden));
  return r.Read(*out);
}

constexpr const char* kGood =
    "depth: 8\non: true\nname: rover\nmode: b\ninner:\n  gain: 2.5\n  xy: [1, 2]\n";

TEST(YamlOptionsReaderTest, ReadsEveryKind) {
  Outer o;
  ASSERT_TRUE(Read(kGood, &o).ok());
  EXPECT_EQ(o.depth, 8);
  EXPECT_TRUE(o.on);
  EXPECT_EQ(o.name, "rover");
  EXPECT_EQ(o.mode, Mode::kB);
  EXPECT_DOUBLE_EQ(o.inner.gain, 2.5);
  EXPECT_EQ(o.inner.xy, (std::vector<double>{1, 2}));
}

struct ErrorCase {
  const char* yaml;
  const char* expected;  // substring of the error
};

TEST(YamlOptionsReaderTest, EveryErrorNamesFileLineAndKey) {
  const ErrorCase cases[] = {
      {"on: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1]}\n", "test.yaml:1:1: missing key 'depth'"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1]}\nextra: 3\n", "test.yaml:6:1: unknown key 'extra'"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1], gian: 2}\n", "unknown key 'inner.gian'"},
      {"depth: 17\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1]}\n", "test.yaml:1:8: key 'depth' = 17 is outside [1, 16] items"},
      {"depth: 2.5\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1]}\n", "key 'depth' must be an integer"},
      {"depth: 8\non: maybe\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1]}\n", "test.yaml:2:5: key 'on' must be true or false"},
      {"depth: 8\non: true\nname: [x]\nmode: a\ninner: {gain: 1, xy: [0, 1]}\n", "key 'name' must be a string"},
      {"depth: 8\non: true\nname: x\nmode: c\ninner: {gain: 1, xy: [0, 1]}\n", "key 'mode' = 'c' is not one of: a, b"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: 3\n", "key 'inner' must be a mapping"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: .nan, xy: [0, 1]}\n", "key 'inner.gain' must be a finite number"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 11, xy: [0, 1]}\n", "key 'inner.gain' = 11 is outside [0, 10] 1/s"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0]}\n", "key 'inner.xy' has 1 values, expected 2"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 9]}\n", "key 'inner.xy' item 1 = 9 is outside [-5, 5] m"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: 3}\n", "key 'inner.xy' must be a list"},
      {"depth: 8\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [2, 1]}\n", "section 'inner': xy must be ascending"},
      {"- 1\n- 2\n", "test.yaml: the document is not a mapping"},
  };
  for (const ErrorCase& c : cases) {
    Outer o;
    const Status s = Read(c.yaml, &o);
    ASSERT_FALSE(s.ok()) << c.yaml;
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.message().find(c.expected), std::string::npos)
        << "expected '" << c.expected << "' in:\n" << s.message();
  }
}

TEST(YamlOptionsReaderTest, ReportsAllErrorsNotJustTheFirst) {
  Outer o;
  const Status s = Read("depth: 99\non: 3\nname: x\nmode: z\ninner: {gain: 1, xy: [0, 1]}\n", &o);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("'depth'"), std::string::npos);
  EXPECT_NE(s.message().find("'on'"), std::string::npos);
  EXPECT_NE(s.message().find("'mode'"), std::string::npos);
}

// An earlier version's copy: keys added since keep their defaults, keys removed since are
// skipped, both noted; a value out of range still fails.
TEST(YamlOptionsReaderTest, EarlierVersionsKeepDefaultsForKeysTheyLack) {
  Outer o;
  YamlOptionsReader r(YAML::Load("depth: 8\non: true\nname: x\ninner: {xy: [0, 1], old: 2}\n"), "test.yaml");
  r.AcceptEarlierVersions();
  ASSERT_TRUE(r.Read(o).ok());
  EXPECT_EQ(o.depth, 8);
  EXPECT_EQ(o.mode, Mode::kA);
  EXPECT_DOUBLE_EQ(o.inner.gain, 1.0);
  ASSERT_EQ(r.notes().size(), 3u);
  EXPECT_NE(r.notes()[0].find("missing key 'mode'"), std::string::npos) << r.notes()[0];
  EXPECT_NE(r.notes()[1].find("missing key 'inner.gain'"), std::string::npos) << r.notes()[1];
  EXPECT_NE(r.notes()[2].find("test.yaml:4:21: unknown key 'inner.old'"), std::string::npos) << r.notes()[2];

  YamlOptionsReader bad(YAML::Load("depth: 99\n"), "test.yaml");
  bad.AcceptEarlierVersions();
  const Status s = bad.Read(o);
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("key 'depth' = 99 is outside"), std::string::npos) << s.message();
  EXPECT_EQ(s.message().find("missing"), std::string::npos) << s.message();
}

TEST(YamlOptionsReaderTest, OverriddenKeysAreBlamedOnTheCommandLine) {
  Outer o;
  const Status s = Read("depth: 99\non: true\nname: x\nmode: a\ninner: {gain: 1, xy: [0, 1]}\n", &o, {"depth"});
  ASSERT_FALSE(s.ok());
  EXPECT_NE(s.message().find("--set depth: key 'depth' = 99"), std::string::npos) << s.message();
}

TEST(YamlOptionsReaderTest, WriterOutputReadsBackToTheSameOptions) {
  Outer o;
  ASSERT_TRUE(Read(kGood, &o).ok());
  const std::string text = OptionsYamlWriter::Write(o);
  Outer back;
  ASSERT_TRUE(Read(text, &back).ok()) << text;
  EXPECT_EQ(back.depth, o.depth);
  EXPECT_EQ(back.name, o.name);
  EXPECT_EQ(back.mode, o.mode);
  EXPECT_EQ(back.inner.xy, o.inner.xy);
  EXPECT_NE(text.find("# [1, 16] items"), std::string::npos) << text;
}

class OverrideTest : public ::testing::Test {
 protected:
  void SetUp() override {
    // One file per test and process: ctest runs the tests of this fixture in parallel.
    const std::string name = ::testing::UnitTest::GetInstance()->current_test_info()->name();
    path_ = (std::filesystem::temp_directory_path() /
             ("cairn_override_test_" + name + "_" + std::to_string(getpid()) + ".yaml"))
                .string();
    std::ofstream(path_) << kGood;
  }
  void TearDown() override { std::filesystem::remove(path_); }
  std::string path_;
};

TEST_F(OverrideTest, SetReplacesExistingKeysOnly) {
  auto doc = LoadYamlWithOverrides(path_, {"inner.gain=7", "name='a b'"});
  ASSERT_TRUE(doc.ok()) << doc.status().ToString();
  Outer o;
  YamlOptionsReader r(doc->root, path_, doc->overridden_keys);
  ASSERT_TRUE(r.Read(o).ok());
  EXPECT_DOUBLE_EQ(o.inner.gain, 7.0);
  EXPECT_EQ(o.name, "a b");
  for (const char* bad : {"inner.gian=1", "nokey=1", "=3", "depth", "depth=[unclosed"}) {
    auto d = LoadYamlWithOverrides(path_, {bad});
    ASSERT_FALSE(d.ok()) << bad;
    EXPECT_NE(d.status().message().find("--set"), std::string::npos) << d.status().message();
  }
}

TEST_F(OverrideTest, MissingAndUnparsableFilesAreReported) {
  EXPECT_EQ(LoadYamlWithOverrides("/nonexistent/cairn.yaml", {}).status().code(), StatusCode::kNotFound);
  std::ofstream(path_) << "a: [1, 2\nb: 3\n";
  auto d = LoadYamlWithOverrides(path_, {});
  ASSERT_FALSE(d.ok());
  EXPECT_NE(d.status().message().find(path_ + ":"), std::string::npos);
  EXPECT_NE(d.status().message().find("not valid YAML"), std::string::npos);
}

}  // namespace
}  // namespace cairn
