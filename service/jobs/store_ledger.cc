#include "jobs/store_ledger.h"

#include <fmt/format.h>

#include <system_error>

#include "jobs/newest_checkpoint.h"
#include "jobs/wall_clock.h"
#include "store/durable_files.h"

namespace seep::service {

StoreLedger::StoreLedger(JobStore& store, std::filesystem::path checkpoint_dir,
                         std::shared_ptr<spdlog::logger> logger,
                         const TestCrashPoints* crash_points)
    : store_(store),
      checkpoint_dir_(std::move(checkpoint_dir)),
      logger_(std::move(logger)),
      crash_points_(crash_points) {}

core::Result<std::optional<JobRecord>> StoreLedger::Claim(const std::string& owner,
                                                          std::chrono::milliseconds lease) {
  // Relaxed: the claimer is a worker of this process, so a power loss that undoes the claim
  // also ends the worker; the job is queued again and its epoch is never held twice.
  return store_.ClaimNextQueued(owner, NowMs(), lease.count(), std::nullopt, std::nullopt,
                                CommitSync::kRelaxed);
}

core::Result<bool> StoreLedger::Heartbeat(const std::string& id, std::int64_t epoch,
                                          std::chrono::milliseconds lease) {
  // The stored expiry is rewritten only once less than half a lease is left: the lease then
  // never has less than half of it to run, and a heartbeat a second writes once every half lease
  // (a write with each commit's WAL pages was most of what a remote worker's beat cost seepd).
  const std::int64_t now = NowMs();
  return store_.Heartbeat(id, epoch, now + lease.count(), now + lease.count() / 2);
}

core::Status StoreLedger::UpdateProgress(const std::string& id, std::int64_t epoch,
                                         const JobProgress& progress) {
  return store_.UpdateProgress(id, epoch, progress);
}

core::Status StoreLedger::AddEvent(const std::string& id, std::int64_t epoch,
                                   const std::string& kind, const std::string& message) {
  return store_.AddLeasedEvent(id, epoch, NowMs(), kind, message);
}

core::Result<std::int64_t> StoreLedger::SaveCheckpoint(const JobRecord& job,
                                                       const CheckpointMeta& meta,
                                                       std::string_view state, std::uint32_t keep,
                                                       CheckpointRole role) {
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::absolute(checkpoint_dir_ / job.id, ec);
  const std::filesystem::path path = dir / fmt::format("ckpt-{:012}.bin", meta.step);
  SEEP_RETURN_IF_ERROR(CreateDirectoriesDurably(dir));
  SEEP_RETURN_IF_ERROR(WriteCheckpointFile(path, meta, state));
  if (crash_points_ != nullptr) crash_points_->Reach(TestCrashPoints::kCheckpointFile);
  CheckpointRecord record;
  record.step = meta.step;
  record.time_s = meta.time_s;
  record.path = path.string();
  record.bytes = static_cast<std::int64_t>(std::filesystem::file_size(path, ec));
  record.attempt = job.attempt;
  record.created_at_ms = NowMs();
  // Unrecorded (a lost lease, a store error), the file is left alone: a newer claim may have
  // written and recorded the same step under the same name, and the start-up sweep removes
  // orphans.
  SEEP_ASSIGN_OR_RETURN(
      const std::vector<CheckpointRecord> dropped,
      store_.RecordCheckpoint(
          job.id, job.lease_epoch, record, keep,
          role == CheckpointRole::kFinalState ? CommitSync::kRelaxed : CommitSync::kDurable));
  for (const CheckpointRecord& old : dropped) {
    // The one just written may be among them (when stale newer records outrank it): keep it.
    if (old.step != record.step) std::filesystem::remove(old.path, ec);
  }
  return record.bytes;
}

core::Result<std::optional<FetchedCheckpoint>> StoreLedger::NewestCheckpoint(
    const JobRecord& job, std::optional<std::uint64_t> below_step) {
  SEEP_ASSIGN_OR_RETURN(const std::vector<CheckpointRecord> records,
                        store_.ListCheckpoints(job.id));
  auto verified = NextVerifiedCheckpoint(job, records, below_step, [&](const SkippedCheckpoint& s) {
    const std::string name = std::filesystem::path(s.record.path).filename().string();
    const std::string why = s.foreign ? "it belongs to another job or scene" : s.why.ToString();
    logger_->warn("job {}: checkpoint {} (step {}) skipped: {}", job.id, name, s.record.step, why);
    if (auto added = AddEvent(job.id, job.lease_epoch, "CHECKPOINT_SKIPPED",
                              fmt::format("{} (step {}): {}", name, s.record.step, why));
        !added.ok()) {
      logger_->warn("job {}: event not stored: {}", job.id, added.ToString());
    }
  });
  if (!verified) return std::optional<FetchedCheckpoint>();
  FetchedCheckpoint fetched;
  fetched.step = verified->record.step;
  fetched.meta = std::move(verified->file.meta);
  fetched.state = std::move(verified->file.state);
  fetched.name = std::filesystem::path(verified->record.path).filename().string();
  return std::optional<FetchedCheckpoint>(std::move(fetched));
}

core::Status StoreLedger::StoreResultSeries(const std::string& id, std::int64_t epoch,
                                            const std::vector<std::string>& columns,
                                            const std::vector<double>& values,
                                            const std::string& state_sha256,
                                            const JobProgress& final_progress) {
  return store_.StoreResultSeries(id, epoch, columns, values, state_sha256, &final_progress);
}

core::Status StoreLedger::Finish(const std::string& id, std::int64_t epoch, JobState state,
                                 const std::string& error_code, const std::string& error_message,
                                 const std::vector<std::pair<std::string, double>>& metrics,
                                 double wall_time_s) {
  return store_.Finish(id, epoch, state, error_code, error_message, metrics, wall_time_s, NowMs());
}

core::Status StoreLedger::ReleaseLease(const std::string& id, std::int64_t epoch) {
  return store_.ReleaseLease(id, epoch);
}

}  // namespace seep::service
