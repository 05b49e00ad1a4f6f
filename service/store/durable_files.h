// Files and folders that survive a crash or power loss, private to their owner (0600 files, 0700
// folders): what the checkpoint files of the data folder are made of.
//
// A file is written whole under a unique temporary name in its own folder (no two writers, in one
// process or two, can pick the same one), fsync'ed, renamed over its final name, and the folder is
// fsync'ed so the rename itself is durable. A folder created on the way is made durable the same
// way, by an fsync of its parent. A temporary name always contains kTempFileMarker, so that a
// start-up sweep can tell the leftovers of an interrupted write.
#pragma once

#include <filesystem>
#include <string_view>

#include "seep/core/status.h"

namespace seep::service {

inline constexpr std::string_view kTempFileMarker = ".tmp-";

// True for a name WriteFileDurably may have left behind (a crash between create and rename).
bool IsTempFileName(std::string_view file_name);

// Creates every missing folder of `dir` with mode 0700, each made durable by an fsync of its
// parent. An existing folder is left as it is.
core::Status CreateDirectoriesDurably(const std::filesystem::path& dir);

// Writes `bytes` to `path` (mode 0600) atomically and durably: after a crash, `path` is either the
// old file or the complete new one. The folder must exist.
core::Status WriteFileDurably(const std::filesystem::path& path, std::string_view bytes);

// Removes a file or an empty folder and fsyncs its parent; a missing one is fine.
core::Status RemoveDurably(const std::filesystem::path& path);

}  // namespace seep::service
