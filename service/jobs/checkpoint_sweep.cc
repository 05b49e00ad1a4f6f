#include "jobs/checkpoint_sweep.h"

#include <fmt/format.h>

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

// Whether the store holds any job, in any state.
core::Result<bool> StoreHasJobs(JobStore& store) {
  SEEP_ASSIGN_OR_RETURN(const auto counts, store.CountByState());
  for (const auto& [state, count] : counts) {
    if (count > 0) return true;
  }
  return false;
}

// `path` as the operator reads it: relative to the data folder (the checkpoint folder's parent).
std::string Shown(const fs::path& path, const fs::path& root) {
  return path.lexically_relative(root.parent_path()).string();
}

// Moves every file under `root` to the same place under `lost` (folders 0700), keeping them whole.
core::Status MoveToLost(const std::vector<fs::path>& files, const fs::path& root,
                        const fs::path& lost, spdlog::logger& log, int* moved) {
  std::error_code ec;
  for (const fs::path& file : files) {
    const fs::path target = lost / file.lexically_relative(root);
    fs::create_directories(target.parent_path(), ec);
    if (!ec) fs::permissions(lost, fs::perms::owner_all, fs::perm_options::replace, ec);
    if (!ec) fs::rename(file, target, ec);
    if (ec) {
      return core::Unavailable(fmt::format("checkpoint sweep: cannot move {} to {}: {}",
                                           Shown(file, root), Shown(target, root), ec.message()));
    }
    log.warn("checkpoint sweep: {} moved to {} (its database was lost; accepted)",
             Shown(file, root), Shown(target, root));
    ++*moved;
  }
  return core::Status::Ok();
}

}  // namespace

core::Result<SweepCounts> SweepCheckpointFolder(JobStore& store,
                                                const std::filesystem::path& checkpoints_dir,
                                                spdlog::logger& log, bool accept_lost_database) {
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

  // Files a crash inside a write left are nobody's state; every other file is some job's.
  std::vector<std::filesystem::path> states;
  for (const std::filesystem::path& file : files) {
    if (!IsTempFileName(file.filename().string())) states.push_back(file);
  }
  SEEP_ASSIGN_OR_RETURN(const bool has_jobs, StoreHasJobs(store));
  if (!has_jobs && !states.empty()) {
    const fs::path lost = LostCheckpointsDir(root);
    if (!accept_lost_database) {
      std::string named;
      for (std::size_t k = 0; k < states.size() && k < 3; ++k) {
        named += (k > 0 ? ", " : "") + Shown(states[k], root);
      }
      return core::FailedPrecondition(fmt::format(
          "the store holds no job, but {} holds {} checkpoint file(s) ({}{}): the database was "
          "lost or replaced, and these files are its jobs' only state. Nothing was removed. Put "
          "the database (seep.db with its -wal file) back, or start with --accept-lost-database "
          "to move the files to {} and begin with an empty store",
          Shown(root, root), states.size(), named, states.size() > 3 ? ", ..." : "",
          Shown(lost, root)));
    }
    SEEP_RETURN_IF_ERROR(MoveToLost(states, root, lost, log, &counts.lost_files));
    std::erase_if(files, [](const fs::path& f) { return !IsTempFileName(f.filename().string()); });
  }

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
      log.info(
          "checkpoint sweep: removed {}: no checkpoint record of its job points to it (a "
          "crash came between the file and its record, or after the record's removal)",
          Shown(file, root));
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
