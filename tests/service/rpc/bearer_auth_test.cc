// BearerAuth without a server: token sources and what the metadata check accepts and refuses.
#include "rpc/bearer_auth.h"

#include <gtest/gtest.h>
#include <unistd.h>

#include <filesystem>
#include <fstream>

namespace seep::service {
namespace {

using Metadata = std::multimap<grpc::string_ref, grpc::string_ref>;

TEST(BearerAuth, AcceptsOnlyTheExactBearerToken) {
  auto auth = BearerAuth::FromToken("abc123");
  ASSERT_TRUE(auth.ok()) << auth.status().ToString();
  EXPECT_TRUE(auth->CheckMetadata({{"authorization", "Bearer abc123"}}).ok());

  const Metadata refused[] = {
      {},                                     // missing
      {{"authorization", "abc123"}},          // no scheme
      {{"authorization", "Basic abc123"}},    // other scheme
      {{"authorization", "Bearer abc12"}},    // prefix
      {{"authorization", "Bearer abc1234"}},  // longer
      {{"authorization", "Bearer abc124"}},   // last byte differs
      {{"authorization", "Bearer "}},         // empty token
      {{"authorization", "Bearer abc123"}, {"authorization", "Bearer abc123"}},  // twice
  };
  for (const Metadata& metadata : refused) {
    EXPECT_EQ(auth->CheckMetadata(metadata).error_code(), grpc::StatusCode::UNAUTHENTICATED);
  }
  EXPECT_NE(auth->CheckMetadata({}).error_message().find("missing 'authorization"),
            std::string::npos);
}

TEST(BearerAuth, ConstantTimeEqualsComparesLengthAndEveryByte) {
  EXPECT_TRUE(ConstantTimeEquals("token", "token"));
  EXPECT_FALSE(ConstantTimeEquals("tokenX", "token"));
  EXPECT_FALSE(ConstantTimeEquals("toke", "token"));
  EXPECT_FALSE(ConstantTimeEquals("tokem", "token"));
  EXPECT_FALSE(ConstantTimeEquals("", "token"));
  EXPECT_FALSE(ConstantTimeEquals("", ""));  // an empty token never authenticates
  // "abab" cycled over "ab" must not pass: the length differs.
  EXPECT_FALSE(ConstantTimeEquals("abab", "ab"));
}

TEST(BearerAuth, RefusesTokensThatCannotBeHeaderValues) {
  EXPECT_FALSE(BearerAuth::FromToken("").ok());
  EXPECT_FALSE(BearerAuth::FromToken("has space").ok());
  EXPECT_FALSE(BearerAuth::FromToken("new\nline").ok());
  EXPECT_FALSE(BearerAuth::FromToken(std::string(4097, 'a')).ok());
  EXPECT_TRUE(BearerAuth::FromToken(std::string(4096, 'a')).ok());
}

TEST(BearerAuth, TokenFileMustExistHoldATokenAndBePrivate) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("seep-bearer-" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  const auto write = [&](const char* name, const char* text, std::filesystem::perms perms) {
    const auto path = dir / name;
    std::ofstream(path) << text;
    std::filesystem::permissions(path, perms);
    return path.string();
  };
  using std::filesystem::perms;
  const perms owner = perms::owner_read | perms::owner_write;

  auto good = BearerAuth::FromFile(write("good", "  tok-1\n", owner));
  ASSERT_TRUE(good.ok()) << good.status().ToString();
  EXPECT_TRUE(good->CheckMetadata({{"authorization", "Bearer tok-1"}}).ok());

  auto missing = BearerAuth::FromFile((dir / "missing").string());
  EXPECT_NE(missing.status().message().find("does not exist"), std::string::npos);
  auto empty = BearerAuth::FromFile(write("empty", " \n", owner));
  EXPECT_NE(empty.status().message().find("is empty"), std::string::npos);
  auto shared = BearerAuth::FromFile(write("shared", "tok-1", owner | perms::group_read));
  EXPECT_NE(shared.status().message().find("chmod 600"), std::string::npos);
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace seep::service
