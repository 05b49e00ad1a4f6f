// Checkpoint files: crash-safe writing and verified reading (proto/seep/v1/checkpoint.proto has
// the layout). The solver state is opaque bytes here; what goes into it is the solver's business.
//
// Writing is atomic (store/durable_files.h): the file is written under a unique temporary name
// in the same directory (mode 0600), fsync'ed, renamed over <path>, and the directory is fsync'ed,
// so after a crash <path> is either the old file or the complete new one. Sizes and offsets are
// 64-bit: a state over 2 GiB reads back like a small one. Reading verifies the magic, the format
// version, every chunk's SHA-256, the chunk count and size, and the whole-file SHA-256: a truncated
// or corrupted file is DATA_LOSS with the reason, a file from a newer format is
// FAILED_PRECONDITION. Which file a resume or GetJobFields takes: jobs/newest_checkpoint.h.
#pragma once

#include <cstdint>
#include <filesystem>
#include <string>
#include <string_view>

#include "seep/core/status.h"
#include "sha256.h"

namespace seep::service {

inline constexpr std::uint32_t kCheckpointFormatVersion = 1;
inline constexpr std::size_t kCheckpointChunkBytes = 1u << 20;

struct CheckpointMeta {
  std::uint32_t format_version = kCheckpointFormatVersion;
  std::string build_id;
  std::string job_id;
  std::string scene_sha256;  // 32 raw bytes
  std::uint64_t step = 0;
  double time_s = 0.0;
};

struct CheckpointFile {
  CheckpointMeta meta;
  std::string state;
};

core::Status WriteCheckpointFile(const std::filesystem::path& path, const CheckpointMeta& meta,
                                 std::string_view state);

core::Result<CheckpointFile> ReadCheckpointFile(const std::filesystem::path& path);

}  // namespace seep::service
