#include "store/durable_files.h"

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_support.h"

namespace seep::service {
namespace {

namespace fs = std::filesystem;

fs::perms Mode(const fs::path& p) { return fs::status(p).permissions() & fs::perms::all; }

std::string ReadAll(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

TEST(DurableFiles, NewFoldersAre0700AndAnExistingOneIsLeftAlone) {
  const fs::path dir = testing::FreshTestDir("durable");
  fs::permissions(dir, fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec);
  const fs::path nested = dir / "a" / "b" / "c";
  ASSERT_TRUE(CreateDirectoriesDurably(nested).ok());
  for (const fs::path& p : {dir / "a", dir / "a" / "b", nested}) {
    EXPECT_EQ(Mode(p), fs::perms::owner_all) << p;
  }
  EXPECT_EQ(Mode(dir), fs::perms::owner_all | fs::perms::group_read | fs::perms::group_exec);
  EXPECT_TRUE(CreateDirectoriesDurably(nested).ok());  // again: nothing to do
  const fs::path file = dir / "plain";
  std::ofstream(file) << "x";
  const core::Status blocked = CreateDirectoriesDurably(file / "below");
  EXPECT_FALSE(blocked.ok());
  EXPECT_NE(blocked.message().find((file / "below").string()), std::string::npos)
      << blocked.message();
  fs::remove_all(dir);
}

TEST(DurableFiles, AWrittenFileIs0600AndNoTemporaryFileStays) {
  const fs::path dir = testing::FreshTestDir("durable");
  const fs::path file = dir / "state.bin";
  ASSERT_TRUE(WriteFileDurably(file, "first").ok());
  ASSERT_TRUE(WriteFileDurably(file, "second").ok());
  EXPECT_EQ(ReadAll(file), "second");
  EXPECT_EQ(Mode(file), fs::perms::owner_read | fs::perms::owner_write);
  int entries = 0;
  for (const auto& e : fs::directory_iterator(dir)) {
    ++entries;
    EXPECT_FALSE(IsTempFileName(e.path().filename().string())) << e.path();
  }
  EXPECT_EQ(entries, 1);
  // A folder that does not exist: an error naming it, and nothing created.
  const core::Status missing = WriteFileDurably(dir / "no" / "x.bin", "y");
  EXPECT_EQ(missing.code(), core::StatusCode::kUnavailable);
  EXPECT_NE(missing.message().find((dir / "no" / "x.bin").string()), std::string::npos);
  EXPECT_FALSE(fs::exists(dir / "no"));
  fs::remove_all(dir);
}

TEST(DurableFiles, TempNamesAreRecognisedAndRemoveToleratesMissingFiles) {
  EXPECT_TRUE(IsTempFileName("ckpt-000000000010.bin.tmp-Ab12Cd"));
  EXPECT_FALSE(IsTempFileName("ckpt-000000000010.bin"));
  const fs::path dir = testing::FreshTestDir("durable");
  std::ofstream(dir / "f") << "x";
  EXPECT_TRUE(RemoveDurably(dir / "f").ok());
  EXPECT_FALSE(fs::exists(dir / "f"));
  EXPECT_TRUE(RemoveDurably(dir / "f").ok());
  fs::remove_all(dir);
}

}  // namespace
}  // namespace seep::service
