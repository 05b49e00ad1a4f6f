#include "store/checkpoint_io.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <atomic>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <thread>
#include <vector>

#include "test_support.h"

namespace seep::service {
namespace {

class CheckpointIoTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = testing::FreshTestDir("ckpt-test"); }
  void TearDown() override { std::filesystem::remove_all(dir_); }

  static CheckpointMeta Meta(std::uint64_t step) {
    CheckpointMeta meta;
    meta.build_id = "0.1.0+test";
    meta.job_id = "j-1";
    meta.scene_sha256 = Sha256("scene");
    meta.step = step;
    meta.time_s = 0.25 * static_cast<double>(step);
    return meta;
  }
  // A state that spans several chunks, with every byte value.
  static std::string State(std::size_t size) {
    std::string state(size, '\0');
    for (std::size_t i = 0; i < size; ++i) state[i] = static_cast<char>((i * 131u + 7u) % 256u);
    return state;
  }
  static std::string ReadAll(const std::filesystem::path& p) {
    std::ifstream in(p, std::ios::binary);
    std::ostringstream s;
    s << in.rdbuf();
    return s.str();
  }
  static void WriteAll(const std::filesystem::path& p, const std::string& bytes) {
    std::ofstream(p, std::ios::binary | std::ios::trunc) << bytes;
  }

  std::filesystem::path dir_;
};

TEST_F(CheckpointIoTest, RoundTripsStateAndMetaAcrossChunks) {
  const auto path = dir_ / "ckpt-100.bin";
  const std::string state = State(2 * kCheckpointChunkBytes + 12345);  // three chunks
  ASSERT_TRUE(WriteCheckpointFile(path, Meta(100), state).ok());
  // Only the file itself, private to its owner: no temporary file left beside it.
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_),
                          std::filesystem::directory_iterator()),
            1);
  EXPECT_EQ(std::filesystem::status(path).permissions() & std::filesystem::perms::all,
            std::filesystem::perms::owner_read | std::filesystem::perms::owner_write);
  auto read = ReadCheckpointFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->state, state);
  EXPECT_EQ(read->meta.step, 100u);
  EXPECT_EQ(read->meta.time_s, 25.0);
  EXPECT_EQ(read->meta.job_id, "j-1");
  EXPECT_EQ(read->meta.build_id, "0.1.0+test");
  EXPECT_EQ(read->meta.scene_sha256, Sha256("scene"));
  EXPECT_EQ(read->meta.format_version, kCheckpointFormatVersion);
}

TEST_F(CheckpointIoTest, EmptyStateAndOverwriteReplaceTheFile) {
  const auto path = dir_ / "ckpt.bin";
  ASSERT_TRUE(WriteCheckpointFile(path, Meta(1), "first").ok());
  ASSERT_TRUE(WriteCheckpointFile(path, Meta(2), "").ok());
  auto read = ReadCheckpointFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  EXPECT_EQ(read->meta.step, 2u);
  EXPECT_TRUE(read->state.empty());
}

// Writers of the same checkpoint at once (a rescued job's hung worker waking up beside its new
// one) never share a temporary file: every write succeeds and the file is one of them, whole.
TEST_F(CheckpointIoTest, ConcurrentWritersOfOnePathNeverMixTheirBytes) {
  const auto path = dir_ / "ckpt-7.bin";
  std::vector<std::thread> writers;
  std::atomic<int> failures{0};
  for (int w = 0; w < 6; ++w) {
    writers.emplace_back([&, w] {
      const std::string state(kCheckpointChunkBytes + 1000 * static_cast<std::size_t>(w),
                              static_cast<char>('a' + w));
      for (int i = 0; i < 10; ++i) {
        if (!WriteCheckpointFile(path, Meta(7), state).ok()) ++failures;
      }
    });
  }
  for (auto& t : writers) t.join();
  EXPECT_EQ(failures.load(), 0);
  auto read = ReadCheckpointFile(path);
  ASSERT_TRUE(read.ok()) << read.status().ToString();
  const char fill = read->state.front();
  ASSERT_GE(fill, 'a');
  ASSERT_LE(fill, 'f');
  EXPECT_EQ(read->state,
            std::string(kCheckpointChunkBytes + 1000 * static_cast<std::size_t>(fill - 'a'), fill));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir_),
                          std::filesystem::directory_iterator()),
            1);
}

TEST_F(CheckpointIoTest, Sha256MatchesTheStandardTestVector) {
  // FIPS 180-2 example: SHA-256("abc").
  const std::string digest = Sha256("abc");
  ASSERT_EQ(digest.size(), 32u);
  EXPECT_EQ(static_cast<unsigned char>(digest[0]), 0xbau);
  EXPECT_EQ(static_cast<unsigned char>(digest[1]), 0x78u);
  EXPECT_EQ(static_cast<unsigned char>(digest[31]), 0xadu);
}

TEST_F(CheckpointIoTest, TruncationAtAnyPointIsDataLoss) {
  const auto path = dir_ / "ckpt.bin";
  ASSERT_TRUE(WriteCheckpointFile(path, Meta(5), State(kCheckpointChunkBytes + 100)).ok());
  const std::string full = ReadAll(path);
  for (const std::size_t keep : {std::size_t{0}, std::size_t{4}, std::size_t{20}, full.size() / 2,
                                 full.size() - 40, full.size() - 1}) {
    WriteAll(path, full.substr(0, keep));
    auto read = ReadCheckpointFile(path);
    ASSERT_FALSE(read.ok()) << "kept " << keep << " bytes";
    EXPECT_EQ(read.status().code(), core::StatusCode::kDataLoss) << read.status().ToString();
  }
}

TEST_F(CheckpointIoTest, AFlippedByteIsDataLoss) {
  const auto path = dir_ / "ckpt.bin";
  ASSERT_TRUE(WriteCheckpointFile(path, Meta(5), State(3000)).ok());
  std::string bytes = ReadAll(path);
  bytes[bytes.size() / 2] = static_cast<char>(bytes[bytes.size() / 2] ^ 0x01);
  WriteAll(path, bytes);
  auto read = ReadCheckpointFile(path);
  ASSERT_FALSE(read.ok());
  EXPECT_EQ(read.status().code(), core::StatusCode::kDataLoss);
  EXPECT_NE(read.status().message().find("checksum"), std::string::npos) << read.status().message();
}

TEST_F(CheckpointIoTest, ForeignFilesAndNewerFormatsAreRefused) {
  const auto foreign = dir_ / "notes.txt";
  WriteAll(foreign, "hello, not a checkpoint");
  EXPECT_EQ(ReadCheckpointFile(foreign).status().code(), core::StatusCode::kDataLoss);
  EXPECT_EQ(ReadCheckpointFile(dir_ / "missing.bin").status().code(), core::StatusCode::kNotFound);

  const auto future = dir_ / "future.bin";
  CheckpointMeta meta = Meta(1);
  meta.format_version = kCheckpointFormatVersion + 1;
  ASSERT_TRUE(WriteCheckpointFile(future, meta, "x").ok());
  auto read = ReadCheckpointFile(future);
  EXPECT_EQ(read.status().code(), core::StatusCode::kFailedPrecondition);
  EXPECT_NE(
      read.status().message().find(fmt::format("format version {}", kCheckpointFormatVersion + 1)),
      std::string::npos)
      << read.status().message();
}

// Format 2 carries the scene itself (what seepd --recover-from-checkpoints rebuilds a job from);
// a format-1 file, which carries its hash alone, is read as it was, with no scene; a scene that
// is not the one its hash names is DATA_LOSS.
TEST_F(CheckpointIoTest, TheSceneTravelsInFormat2AndFormat1IsStillRead) {
  CheckpointMeta with_scene = Meta(7);
  with_scene.scene = "scene";  // Meta's scene_sha256 is Sha256("scene")
  ASSERT_TRUE(WriteCheckpointFile(dir_ / "v2.bin", with_scene, "state").ok());
  auto v2 = ReadCheckpointFile(dir_ / "v2.bin");
  ASSERT_TRUE(v2.ok()) << v2.status().ToString();
  EXPECT_EQ(v2->meta.format_version, 2u);
  EXPECT_EQ(v2->meta.scene, "scene");

  CheckpointMeta v1_meta = Meta(7);
  v1_meta.format_version = 1;
  ASSERT_TRUE(WriteCheckpointFile(dir_ / "v1.bin", v1_meta, "state").ok());
  auto v1 = ReadCheckpointFile(dir_ / "v1.bin");
  ASSERT_TRUE(v1.ok()) << v1.status().ToString();
  EXPECT_EQ(v1->meta.format_version, 1u);
  EXPECT_TRUE(v1->meta.scene.empty());
  EXPECT_EQ(v1->state, "state");

  CheckpointMeta mismatched = Meta(7);
  mismatched.scene = "another scene";
  ASSERT_TRUE(WriteCheckpointFile(dir_ / "bad.bin", mismatched, "state").ok());
  auto bad = ReadCheckpointFile(dir_ / "bad.bin");
  EXPECT_EQ(bad.status().code(), core::StatusCode::kDataLoss);
  EXPECT_NE(bad.status().message().find("its scene does not have the scene's SHA-256"),
            std::string::npos)
      << bad.status().message();
}

// A client sees a checkpoint's errors (in events, a job's error, DATA_LOSS): they name it from
// the data folder on, never by the server's absolute path.
TEST_F(CheckpointIoTest, ErrorsNameTheFileFromTheDataFolderOn) {
  const auto missing = dir_ / "checkpoints" / "j-1" / "000000000012.ckpt";
  const auto read = ReadCheckpointFile(missing);
  EXPECT_EQ(read.status().code(), core::StatusCode::kNotFound);
  EXPECT_EQ(read.status().message(), "checkpoint: checkpoints/j-1/000000000012.ckpt: cannot open");
  // A write into a folder that cannot be made (a file stands where it should be).
  WriteAll(dir_ / "checkpoints", "a file, not a folder");
  const core::Status written = WriteCheckpointFile(missing, Meta(12), "x");
  ASSERT_FALSE(written.ok());
  EXPECT_EQ(written.message().find(dir_.string()), std::string::npos) << written.message();
  EXPECT_NE(written.message().find("checkpoints/j-1"), std::string::npos) << written.message();
}

}  // namespace
}  // namespace seep::service
