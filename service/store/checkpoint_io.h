// Checkpoints: their bytes (proto/seep/v1/checkpoint.proto has the layout), crash-safe writing
// of their files and verified reading. The solver state is opaque bytes here; what goes into it
// is the solver's business. A checkpoint lives in a file, or (a small final state, see
// kStoredCheckpointMaxBytes) in its record in the store: the same bytes, verified the same way.
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

#include "job_record.h"
#include "seep/core/status.h"
#include "sha256.h"

namespace seep::service {

// 2: the header carries the scene itself (1: only its hash); both are read.
inline constexpr std::uint32_t kCheckpointFormatVersion = 2;
inline constexpr std::size_t kCheckpointChunkBytes = 1u << 20;

struct CheckpointMeta {
  std::uint32_t format_version = kCheckpointFormatVersion;
  std::string build_id;
  std::string job_id;
  std::string scene_sha256;  // 32 raw bytes
  std::string scene;         // the serialized scene (format 2 on; empty when written by 1)
  std::uint64_t step = 0;
  double time_s = 0.0;
};

struct CheckpointFile {
  CheckpointMeta meta;
  std::string state;
};

// A run's final state whose checkpoint is at most this many bytes is kept in its record, in the
// transaction that records the run's success, instead of in a file of its own. For a sweep of
// small jobs a file meant a folder, an inode and three fsyncs a job, and their I/O interrupts
// cost more CPU than the rest of the job's bookkeeping; a blob this small is also read back
// faster from SQLite than from a file. Larger states, and every resume point, go to files.
inline constexpr std::size_t kStoredCheckpointMaxBytes = 256u << 10;

// The checkpoint's bytes: magic, header, chunks with their SHA-256, trailer with the whole's.
std::string EncodeCheckpoint(const CheckpointMeta& meta, std::string_view state);
// Verifies and parses a checkpoint's bytes; `name` names it in errors.
core::Result<CheckpointFile> DecodeCheckpoint(std::string_view bytes, std::string_view name);

// A checkpoint lives at <data folder>/checkpoints/<job id>/<file>. What reaches a client (an
// event, a job's error, a DATA_LOSS) names it from the data folder on: `message` with every
// occurrence of the data folder's absolute path (and its '/') taken out.
std::string HideDataFolder(std::string message, const std::filesystem::path& checkpoint_path);

core::Status WriteCheckpointBytes(const std::filesystem::path& path, std::string_view bytes);
core::Status WriteCheckpointFile(const std::filesystem::path& path, const CheckpointMeta& meta,
                                 std::string_view state);

core::Result<CheckpointFile> ReadCheckpointFile(const std::filesystem::path& path);
// The recorded checkpoint, from its file or (path empty) from the bytes the store holds.
core::Result<CheckpointFile> ReadCheckpoint(const CheckpointRecord& record);
// Its name in logs and events: the file's name, or the one it would have, marked as in the store.
std::string CheckpointName(const CheckpointRecord& record);

}  // namespace seep::service
