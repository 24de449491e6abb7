#include "daemon/comms/curve_keys.h"

#include <stdlib.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

namespace cairn {
namespace {

namespace fs = std::filesystem;

class CurveKeysTest : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string pattern = (fs::temp_directory_path() / "cairn_keys_XXXXXX").string();
    dir_ = mkdtemp(pattern.data());
  }
  void TearDown() override { fs::remove_all(dir_); }
  void WriteFile(const std::string& name, const std::string& text, mode_t mode = 0600) {
    const std::string path = dir_ + "/" + name;
    std::ofstream(path) << text;
    chmod(path.c_str(), mode);
  }
  mode_t Mode(const std::string& name) {
    struct stat st {};
    stat((dir_ + "/" + name).c_str(), &st);
    return st.st_mode & 0777;
  }
  std::string dir_;
};

TEST_F(CurveKeysTest, WrittenKeysLoadBackWithOwnerOnlySecrets) {
  auto keys = CurveKeys::Generate();
  ASSERT_TRUE(keys.ok()) << keys.status().ToString();
  EXPECT_TRUE(CurveKeys::IsValidKey(keys->public_key));
  EXPECT_NE(keys->public_key, keys->secret_key);
  ASSERT_TRUE(CurveKeys::Write(dir_, "rover", *keys, false).ok());
  EXPECT_EQ(Mode("rover.key"), 0600u);
  EXPECT_EQ(Mode("rover.pub"), 0644u);
  auto loaded = CurveKeys::LoadSecret(dir_ + "/rover.key");
  ASSERT_TRUE(loaded.ok()) << loaded.status().ToString();
  EXPECT_EQ(loaded->public_key, keys->public_key);
  EXPECT_EQ(loaded->secret_key, keys->secret_key);
  auto pub = CurveKeys::LoadPublic(dir_ + "/rover.pub");
  ASSERT_TRUE(pub.ok()) << pub.status().ToString();
  EXPECT_EQ(*pub, keys->public_key);
  // A .pub file never carries the secret.
  std::ifstream in(dir_ + "/rover.pub");
  const std::string text((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  EXPECT_EQ(text.find(keys->secret_key), std::string::npos);
}

TEST_F(CurveKeysTest, AnExistingKeyIsReplacedOnlyWhenAsked) {
  auto first = CurveKeys::Generate();
  auto second = CurveKeys::Generate();
  ASSERT_TRUE(first.ok() && second.ok());
  ASSERT_TRUE(CurveKeys::Write(dir_, "rover", *first, false).ok());
  const Status again = CurveKeys::Write(dir_, "rover", *second, false);
  EXPECT_EQ(again.code(), StatusCode::kAlreadyExists) << again.ToString();
  EXPECT_EQ(CurveKeys::LoadSecret(dir_ + "/rover.key")->secret_key, first->secret_key);
  ASSERT_TRUE(CurveKeys::Write(dir_, "rover", *second, true).ok());
  EXPECT_EQ(CurveKeys::LoadSecret(dir_ + "/rover.key")->secret_key, second->secret_key);
  EXPECT_EQ(Mode("rover.key"), 0600u);
}

TEST_F(CurveKeysTest, BadKeyFilesNameTheFileAndLine) {
  auto keys = CurveKeys::Generate();
  auto other = CurveKeys::Generate();
  ASSERT_TRUE(keys.ok() && other.ok());
  const std::string good = "public-key " + keys->public_key + "\nsecret-key " + keys->secret_key + "\n";

  WriteFile("short.key", "# a comment\npublic-key " + keys->public_key + "\nsecret-key abc\n");
  auto r = CurveKeys::LoadSecret(dir_ + "/short.key");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("short.key:3"), std::string::npos) << r.status().ToString();

  WriteFile("mismatch.key", "public-key " + other->public_key + "\nsecret-key " + keys->secret_key + "\n");
  r = CurveKeys::LoadSecret(dir_ + "/mismatch.key");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("not the one of its secret-key"), std::string::npos) << r.status().ToString();

  WriteFile("missing.key", "public-key " + keys->public_key + "\n");
  r = CurveKeys::LoadSecret(dir_ + "/missing.key");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("secret-key"), std::string::npos);

  WriteFile("unknown.key", good + "colour blue\n");
  r = CurveKeys::LoadSecret(dir_ + "/unknown.key");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("unknown.key:3"), std::string::npos) << r.status().ToString();

  WriteFile("open.key", good, 0644);
  r = CurveKeys::LoadSecret(dir_ + "/open.key");
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.status().message().find("readable by others"), std::string::npos) << r.status().ToString();

  EXPECT_FALSE(CurveKeys::LoadSecret(dir_ + "/absent.key").ok());
  WriteFile("secret.pub", good, 0644);
  EXPECT_FALSE(CurveKeys::LoadPublic(dir_ + "/secret.pub").ok());
  // Z85 that decodes past 2^32 in a group is not a key.
  EXPECT_FALSE(CurveKeys::IsValidKey(std::string(40, '#')));
  EXPECT_FALSE(CurveKeys::IsValidKey(keys->public_key.substr(1)));
}

}  // namespace
}  // namespace cairn
