#include "jobs/store_ledger.h"

#include <fmt/format.h>

#include <system_error>

#include "jobs/newest_checkpoint.h"
#include "jobs/wall_clock.h"
#include "store/checkpoint_io.h"
#include "store/durable_files.h"

namespace seep::service {

StoreLedger::StoreLedger(JobStore& store, std::filesystem::path checkpoint_dir,
                         std::shared_ptr<spdlog::logger> logger,
                         const TestCrashPoints* crash_points, std::optional<JobKind> claims)
    : store_(store),
      checkpoint_dir_(std::move(checkpoint_dir)),
      logger_(std::move(logger)),
      crash_points_(crash_points),
      claims_(claims) {}

core::Result<std::optional<JobRecord>> StoreLedger::Claim(const std::string& owner,
                                                          std::chrono::milliseconds lease) {
  // Relaxed: the claimer is a worker of this process, so a power loss that undoes the claim
  // also ends the worker; the job is queued again and its epoch is never held twice.
  return store_.ClaimNextQueued(owner, NowMs(), lease.count(), claims_, std::nullopt,
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

std::filesystem::path StoreLedger::CheckpointPath(const JobRecord& job, std::uint64_t step) const {
  std::error_code ec;
  return std::filesystem::absolute(checkpoint_dir_ / job.id, ec) /
         fmt::format("ckpt-{:012}.bin", step);
}

void StoreLedger::RemoveDropped(const std::vector<CheckpointRecord>& dropped,
                                std::uint64_t kept_step) const {
  for (const CheckpointRecord& old : dropped) {
    // The one just written may be among them (when stale newer records outrank it): keep it.
    if (old.step == kept_step || old.path.empty()) continue;
    std::error_code ec;
    std::filesystem::remove(old.path, ec);
  }
}

core::Result<std::int64_t> StoreLedger::SaveCheckpoint(const JobRecord& job,
                                                       const CheckpointMeta& meta,
                                                       std::string_view state, std::uint32_t keep,
                                                       CheckpointRole role) {
  const std::filesystem::path path = CheckpointPath(job, meta.step);
  const std::string bytes = EncodeCheckpoint(meta, state);
  SEEP_RETURN_IF_ERROR(store_.free_space().CheckRoom(
      fmt::format("the checkpoint at step {} is not written", meta.step), bytes.size()));
  SEEP_RETURN_IF_ERROR(CreateDirectoriesDurably(path.parent_path()));
  SEEP_RETURN_IF_ERROR(WriteCheckpointBytes(path, bytes));
  if (crash_points_ != nullptr) crash_points_->Reach(TestCrashPoints::kCheckpointFile);
  CheckpointRecord record;
  record.step = meta.step;
  record.time_s = meta.time_s;
  record.path = path.string();
  record.bytes = static_cast<std::int64_t>(bytes.size());
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
  RemoveDropped(dropped, record.step);
  return record.bytes;
}

core::Result<FinalStateKept> StoreLedger::RecordSuccess(
    const JobRecord& job, std::int64_t epoch, const std::optional<FinalState>& final_state,
    const RunSuccess& run) {
  FinalStateKept kept;
  std::optional<CheckpointRecord> record;
  if (final_state) {
    record.emplace();
    record->step = final_state->meta.step;
    record->time_s = final_state->meta.time_s;
    record->attempt = job.attempt;
    record->created_at_ms = NowMs();
    std::string bytes = EncodeCheckpoint(final_state->meta, final_state->state);
    record->bytes = static_cast<std::int64_t>(bytes.size());
    if (bytes.size() <= kStoredCheckpointMaxBytes) {
      record->content = std::move(bytes);
    } else {
      const std::filesystem::path path = CheckpointPath(job, record->step);
      // The success stands without it when the disk is low: kept as an event, not a file.
      kept.failure = store_.free_space().CheckRoom("the final state is not kept", bytes.size());
      if (kept.failure.ok()) kept.failure = CreateDirectoriesDurably(path.parent_path());
      if (kept.failure.ok()) kept.failure = WriteCheckpointBytes(path, bytes);
      if (!kept.failure.ok()) {
        kept.failure =
            core::Status(kept.failure.code(), HideDataFolder(kept.failure.message(), path));
      }
      record->path = path.string();
    }
    if (!kept.failure.ok()) {
      record.reset();
      if (auto s = AddFinalStateFailedEvent(job, epoch, final_state->meta.step, kept.failure);
          !s.ok()) {
        logger_->warn("job {}: event not stored: {}", job.id, s.ToString());
      }
    }
  }
  if (crash_points_ != nullptr) crash_points_->Reach(TestCrashPoints::kFinalState);
  SEEP_ASSIGN_OR_RETURN(
      const std::vector<CheckpointRecord> dropped,
      store_.RecordSuccess(job.id, epoch, run, record ? &*record : nullptr,
                           final_state ? final_state->keep : 1, NowMs(), CommitSync::kWindowed));
  if (record) {
    RemoveDropped(dropped, record->step);
    kept.bytes = record->bytes;
  }
  return kept;
}

core::Result<std::optional<FetchedCheckpoint>> StoreLedger::NewestCheckpoint(
    const JobRecord& job, std::optional<std::uint64_t> below_step) {
  SEEP_ASSIGN_OR_RETURN(const std::vector<CheckpointRecord> records,
                        store_.ListCheckpoints(job.id));
  auto verified = NextVerifiedCheckpoint(job, records, below_step, [&](const SkippedCheckpoint& s) {
    const std::string name = CheckpointName(s.record);
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
  fetched.name = CheckpointName(verified->record);
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
  // A worker process's success: its final state was uploaded, its success not yet recorded
  // (seepd's own threads record theirs through RecordSuccess).
  if (crash_points_ != nullptr && state == JobState::kSucceeded) {
    crash_points_->Reach(TestCrashPoints::kFinalState);
  }
  return store_.Finish(id, epoch, state, error_code, error_message, metrics, wall_time_s, NowMs());
}

core::Status StoreLedger::ReleaseLease(const std::string& id, std::int64_t epoch) {
  return store_.ReleaseLease(id, epoch);
}

}  // namespace seep::service
