#include "jobs/checkpoint_removal.h"

#include <filesystem>
#include <set>

#include "store/durable_files.h"

namespace seep::service {

RemovedFiles RemoveCheckpointFiles(std::span<const CheckpointRecord> records, spdlog::logger& log) {
  RemovedFiles removed;
  std::set<std::filesystem::path> folders;
  for (const CheckpointRecord& record : records) {
    if (record.path.empty()) continue;  // the store held its bytes: gone with its record
    const std::filesystem::path path(record.path);
    std::error_code ec;
    const bool existed = std::filesystem::exists(path, ec);
    if (core::Status s = RemoveDurably(path); !s.ok()) {
      log.warn("checkpoint file not removed (the next start's sweep will): {}", s.message());
      continue;
    }
    if (existed) {
      ++removed.files;
      removed.bytes += static_cast<std::uint64_t>(record.bytes);
    }
    if (path.has_parent_path()) folders.insert(path.parent_path());
  }
  for (const std::filesystem::path& folder : folders) {
    std::error_code ec;
    if (std::filesystem::is_empty(folder, ec) && !ec) (void)RemoveDurably(folder);
  }
  return removed;
}

}  // namespace seep::service
