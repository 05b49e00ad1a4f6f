#include "jobs/checkpoint_recovery.h"

#include <fmt/format.h>

#include <algorithm>
#include <system_error>
#include <utility>

#include "jobs/checkpoint_sweep.h"
#include "jobs/wall_clock.h"
#include "seep/v1/scene.pb.h"
#include "store/checkpoint_io.h"

namespace seep::service {
namespace {

namespace fs = std::filesystem;

// A folder named as seepd names a job's: its id.
bool IsJobFolderName(const std::string& name) {
  return name.size() > 2 && name.size() <= 64 && name.rfind("j-", 0) == 0 &&
         std::all_of(name.begin(), name.end(), [](char c) {
           return (c >= '0' && c <= '9') || (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') ||
                  c == '-' || c == '_';
         });
}

bool IsCheckpointFileName(const std::string& name) {
  return name.rfind("ckpt-", 0) == 0 && name.size() > 9 &&
         name.compare(name.size() - 4, 4, ".bin") == 0;
}

struct ReadableCheckpoint {
  fs::path path;
  CheckpointFile file;
  std::int64_t bytes = 0;
};

// What one job folder can be rebuilt from: its files that verify, belong to it and carry a
// scene, those of its newest one's scene; or why none.
struct FolderReading {
  std::vector<ReadableCheckpoint> usable;
  std::string why_not;
};

FolderReading ReadFolder(const fs::path& folder, spdlog::logger& log) {
  FolderReading reading;
  const std::string id = folder.filename().string();
  std::vector<ReadableCheckpoint> carrying_scene;
  int unreadable = 0;
  int without_scene = 0;
  std::error_code ec;
  for (const auto& entry : fs::directory_iterator(folder, ec)) {
    const std::string name = entry.path().filename().string();
    if (!entry.is_regular_file() || !IsCheckpointFileName(name)) continue;
    auto file = ReadCheckpointFile(entry.path());
    if (!file.ok() || file->meta.job_id != id) {
      ++unreadable;
      log.warn("recovery: {}/{}: {}", id, name,
               file.ok() ? fmt::format("belongs to job {}", file->meta.job_id)
                         : file.status().message());
      continue;
    }
    if (file->meta.scene.empty()) {
      ++without_scene;
      continue;
    }
    const auto size = fs::file_size(entry.path(), ec);
    carrying_scene.push_back({entry.path(), std::move(*file), ec ? 0 : std::int64_t(size)});
  }
  if (carrying_scene.empty()) {
    reading.why_not = fmt::format(
        "no checkpoint file to rebuild it from ({} unreadable, {} of format 1, which "
        "carries only the scene's hash)",
        unreadable, without_scene);
    return reading;
  }
  std::sort(carrying_scene.begin(), carrying_scene.end(),
            [](const auto& a, const auto& b) { return a.file.meta.step < b.file.meta.step; });
  const std::string& scene_sha256 = carrying_scene.back().file.meta.scene_sha256;
  for (auto& checkpoint : carrying_scene) {
    if (checkpoint.file.meta.scene_sha256 == scene_sha256) {
      reading.usable.push_back(std::move(checkpoint));
    }
  }
  return reading;
}

// Moves a job folder under `to` (whole), unless one of that name is there already.
core::Status MoveFolder(const fs::path& folder, const fs::path& to) {
  std::error_code ec;
  fs::create_directories(to, ec);
  const fs::path target = to / folder.filename();
  if (fs::exists(target, ec)) {
    return core::AlreadyExists(fmt::format("{} exists already", target.filename().string()));
  }
  fs::rename(folder, target, ec);
  if (ec) return core::Unavailable(fmt::format("cannot move it: {}", ec.message()));
  return core::Status::Ok();
}

}  // namespace

core::Result<RecoveryReport> RecoverFromCheckpoints(JobStore& store,
                                                    const fs::path& checkpoints_dir,
                                                    spdlog::logger& log) {
  SEEP_ASSIGN_OR_RETURN(const auto counts, store.CountByState());
  std::int64_t jobs_in_store = 0;
  for (const auto& [state, count] : counts) jobs_in_store += count;
  if (jobs_in_store > 0) {
    return core::FailedPrecondition(fmt::format(
        "--recover-from-checkpoints: the store holds {} job(s); recovery only fills an empty "
        "store (after seep.db was lost), and nothing was changed",
        jobs_in_store));
  }
  const fs::path lost_dir = LostCheckpointsDir(checkpoints_dir);
  std::error_code ec;
  // An accepted loss moved the folders away: they come back first.
  if (fs::is_directory(lost_dir, ec)) {
    for (const auto& entry : fs::directory_iterator(lost_dir, ec)) {
      if (!entry.is_directory() || !IsJobFolderName(entry.path().filename().string())) continue;
      if (auto moved = MoveFolder(entry.path(), checkpoints_dir); !moved.ok()) {
        log.warn("recovery: lost-checkpoints/{} left where it is: {}",
                 entry.path().filename().string(), moved.message());
      }
    }
  }
  RecoveryReport report;
  std::vector<fs::path> folders;
  for (const auto& entry : fs::directory_iterator(checkpoints_dir, ec)) {
    if (entry.is_directory() && IsJobFolderName(entry.path().filename().string())) {
      folders.push_back(entry.path());
    }
  }
  std::sort(folders.begin(), folders.end());
  // First what cannot be rebuilt moves away (a failure stops recovery before anything is
  // stored: a file left without a record would look like an orphan to the sweep), then the rest
  // is stored.
  std::vector<std::pair<fs::path, JobRecord>> rebuilt;
  std::vector<std::vector<CheckpointRecord>> rebuilt_records;
  for (const fs::path& folder : folders) {
    const std::string id = folder.filename().string();
    FolderReading reading = ReadFolder(folder, log);
    std::string why_not = reading.why_not;
    v1::Scene scene;
    if (why_not.empty() && !scene.ParseFromString(reading.usable.back().file.meta.scene)) {
      why_not = "its newest checkpoint's scene does not parse as seep.v1.Scene";
    }
    if (!why_not.empty()) {
      if (auto moved = MoveFolder(folder, lost_dir); !moved.ok()) {
        return core::Unavailable(fmt::format(
            "--recover-from-checkpoints: job folder {} cannot be rebuilt ({}) nor moved to "
            "lost-checkpoints ({}); nothing was stored",
            id, why_not, moved.message()));
      }
      report.unrecoverable.push_back(fmt::format("{}: {}", id, why_not));
      log.warn("recovery: job {} not recovered, its folder moved to lost-checkpoints: {}", id,
               why_not);
      continue;
    }
    const ReadableCheckpoint& newest = reading.usable.back();
    JobRecord job;
    job.id = id;
    job.name = scene.name();
    job.scene = newest.file.meta.scene;
    job.build_id = newest.file.meta.build_id;
    job.created_at_ms = NowMs();
    job.kind = JobKind::kSimulation;
    std::vector<CheckpointRecord> records;
    for (const ReadableCheckpoint& c : reading.usable) {
      CheckpointRecord record;
      record.step = c.file.meta.step;
      record.time_s = c.file.meta.time_s;
      record.path = c.path.string();
      record.bytes = c.bytes;
      record.created_at_ms = job.created_at_ms;
      records.push_back(std::move(record));
    }
    rebuilt.emplace_back(folder, std::move(job));
    rebuilt_records.push_back(std::move(records));
  }
  for (std::size_t i = 0; i < rebuilt.size(); ++i) {
    const JobRecord& job = rebuilt[i].second;
    const std::vector<CheckpointRecord>& records = rebuilt_records[i];
    const std::string note = fmt::format(
        "rebuilt from {} checkpoint file(s), steps {} to {}, after the database was lost "
        "(seepd --recover-from-checkpoints); it continues from step {}. Labels, priority and "
        "any result were not in the files",
        records.size(), records.front().step, records.back().step, records.back().step);
    SEEP_RETURN_IF_ERROR(store.InsertRecovered(job, records, note));
    ++report.jobs;
    report.checkpoint_files += static_cast<int>(records.size());
    log.info("recovery: job {} ('{}') {}", job.id, job.name, note);
  }
  return report;
}

}  // namespace seep::service
