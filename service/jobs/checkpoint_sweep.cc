#include "jobs/checkpoint_sweep.h"

#include <set>
#include <string>
#include <system_error>
#include <vector>

#include "store/durable_files.h"

namespace seep::service {
namespace {

namespace fs = std::filesystem;

// 1 when `path` had other permission bits than `mode` and now has `mode`, else 0.
int MakePrivate(const fs::path& path, fs::perms mode) {
  std::error_code ec;
  const fs::perms now = fs::status(path, ec).permissions() & fs::perms::all;
  if (ec || now == mode) return 0;
  fs::permissions(path, mode, fs::perm_options::replace, ec);
  return ec ? 0 : 1;
}

}  // namespace

core::Result<SweepCounts> SweepCheckpointFolder(JobStore& store,
                                                const std::filesystem::path& checkpoints_dir,
                                                spdlog::logger& log) {
  SweepCounts counts;
  std::error_code ec;
  const std::filesystem::path root =
      std::filesystem::absolute(checkpoints_dir, ec).lexically_normal();
  if (!std::filesystem::is_directory(root, ec)) return counts;
  SEEP_ASSIGN_OR_RETURN(const std::vector<std::filesystem::path> recorded,
                        store.AllCheckpointPaths());
  const std::set<std::filesystem::path> keep(recorded.begin(), recorded.end());

  std::vector<std::filesystem::path> files;
  std::vector<std::filesystem::path> folders;
  for (auto it = std::filesystem::recursive_directory_iterator(root, ec);
       !ec && it != std::filesystem::recursive_directory_iterator(); it.increment(ec)) {
    const std::filesystem::path path = it->path().lexically_normal();
    if (it->is_directory(ec)) {
      folders.push_back(path);
    } else if (!keep.contains(path)) {
      files.push_back(path);
    } else {
      counts.tightened += MakePrivate(path, fs::perms::owner_read | fs::perms::owner_write);
    }
  }
  counts.tightened += MakePrivate(root, fs::perms::owner_all);
  if (ec)
    return core::Unavailable("checkpoint sweep: cannot list " + root.string() + ": " +
                             ec.message());

  for (const std::filesystem::path& file : files) {
    const std::uintmax_t size = std::filesystem::file_size(file, ec);
    if (core::Status s = RemoveDurably(file); !s.ok()) {
      log.warn("checkpoint sweep: {}", s.message());
      ++counts.failures;
      continue;
    }
    counts.bytes += ec ? 0 : size;
    if (IsTempFileName(file.filename().string())) {
      ++counts.temp_files;
    } else {
      ++counts.orphan_files;
    }
  }
  // Deepest first, so that a folder emptied by its children's removal goes too.
  for (auto it = folders.rbegin(); it != folders.rend(); ++it) {
    if (!std::filesystem::is_empty(*it, ec) || ec) {
      counts.tightened += MakePrivate(*it, fs::perms::owner_all);
      continue;
    }
    if (core::Status s = RemoveDurably(*it); !s.ok()) {
      log.warn("checkpoint sweep: {}", s.message());
      ++counts.failures;
      continue;
    }
    ++counts.empty_folders;
  }
  if (counts.orphan_files + counts.temp_files + counts.empty_folders + counts.failures +
          counts.tightened >
      0) {
    log.info(
        "checkpoint sweep of {}: removed {} orphan file(s) (no checkpoint record), {} temporary "
        "file(s) of interrupted writes, {} empty folder(s); {} bytes freed, {} could not be "
        "removed; {} kept file(s) or folder(s) made private",
        root.string(), counts.orphan_files, counts.temp_files, counts.empty_folders, counts.bytes,
        counts.failures, counts.tightened);
  }
  return counts;
}

}  // namespace seep::service
