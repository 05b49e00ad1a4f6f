#include "jobs/checkpoint_keeper.h"

#include <fmt/format.h>

#include <system_error>

#include "codec/simulation_state_codec.h"
#include "jobs/newest_checkpoint.h"
#include "jobs/wall_clock.h"
#include "store/checkpoint_io.h"
#include "store/durable_files.h"

namespace seep::service {
CheckpointKeeper::CheckpointKeeper(JobStore& store, const CheckpointPolicy& policy,
                                   const JobRecord& job, std::string build_id,
                                   std::shared_ptr<spdlog::logger> log)
    : store_(store),
      policy_(policy),
      job_(job),
      build_id_(std::move(build_id)),
      scene_sha256_(Sha256(job.scene)),
      log_(std::move(log)),
      last_time_(std::chrono::steady_clock::now()) {}

void CheckpointKeeper::Event(const std::string& kind, const std::string& message) {
  if (auto s = store_.AddEvent(job_.id, NowMs(), kind, message); !s.ok()) {
    log_->warn("event not stored: {}", s.ToString());
  }
}

std::optional<std::uint64_t> CheckpointKeeper::RestoreNewest(core::Simulation& sim) {
  auto records = store_.ListCheckpoints(job_.id);
  if (!records.ok()) {
    log_->warn("checkpoints not listed ({}); starting from the beginning",
               records.status().ToString());
    return std::nullopt;
  }
  const auto restored = LoadNewestCheckpoint(job_, *records, sim, [&](const SkippedCheckpoint& s) {
    const std::string name = std::filesystem::path(s.record.path).filename().string();
    const std::string why = s.foreign ? "it belongs to another job or scene" : s.why.ToString();
    log_->warn("checkpoint {} (step {}) skipped: {}", name, s.record.step, why);
    Event("CHECKPOINT_SKIPPED", fmt::format("{} (step {}): {}", name, s.record.step, why));
  });
  if (!restored) return std::nullopt;
  const std::string name = std::filesystem::path(restored->record.path).filename().string();
  if (restored->meta.build_id != build_id_) {
    const std::string note = fmt::format(
        "checkpoint written by build {}, continued by build {}: bit-identity with an "
        "uninterrupted run is promised only for the same build",
        restored->meta.build_id, build_id_);
    log_->warn("{}", note);
    Event("BUILD_CHANGED", note);
  }
  last_step_ = sim.step();
  last_time_ = std::chrono::steady_clock::now();
  log_->info("resumed from checkpoint {} at step {} (t = {} s)", name, sim.step(), sim.time_s());
  Event("RESUMED", fmt::format("from {} at step {} of {}", name, sim.step(), sim.total_steps()));
  return sim.step();
}

core::Status CheckpointKeeper::MaybeWrite(const core::Simulation& sim) {
  if (!enabled() || sim.finished()) return core::Status::Ok();  // the end writes its own
  const bool by_steps = policy_.every_steps > 0 && sim.step() - last_step_ >= policy_.every_steps;
  const bool by_time = policy_.interval.count() > 0 &&
                       std::chrono::steady_clock::now() - last_time_ >= policy_.interval;
  if (!by_steps && !by_time) return core::Status::Ok();
  return Write(sim);
}

core::Status CheckpointKeeper::Write(const core::Simulation& sim) {
  if (!enabled()) return core::Status::Ok();
  const auto start = std::chrono::steady_clock::now();
  return WriteState(sim, SerializeSimulationState(sim.TakeSnapshot()), start);
}

core::Status CheckpointKeeper::Write(const core::Simulation& sim, std::string_view state) {
  if (!enabled()) return core::Status::Ok();
  return WriteState(sim, state, std::chrono::steady_clock::now());
}

core::Status CheckpointKeeper::WriteState(const core::Simulation& sim, std::string_view state,
                                          std::chrono::steady_clock::time_point start) {
  last_step_ = sim.step();
  last_time_ = start;
  std::error_code ec;
  const std::filesystem::path dir = std::filesystem::absolute(policy_.dir / job_.id, ec);
  const std::filesystem::path path = dir / fmt::format("ckpt-{:012}.bin", sim.step());
  CheckpointMeta meta;
  meta.build_id = build_id_;
  meta.job_id = job_.id;
  meta.scene_sha256 = scene_sha256_;
  meta.step = sim.step();
  meta.time_s = sim.time_s();
  core::Status written = CreateDirectoriesDurably(dir);
  if (written.ok()) written = WriteCheckpointFile(path, meta, state);
  if (const core::Status& s = written; !s.ok()) {
    log_->warn("checkpoint at step {} not written: {}", sim.step(), s.ToString());
    Event("CHECKPOINT_FAILED", fmt::format("step {}: {}", sim.step(), s.ToString()));
    return core::Status::Ok();
  }
  if (policy_.crash_points != nullptr)
    policy_.crash_points->Reach(TestCrashPoints::kCheckpointFile);
  CheckpointRecord record;
  record.step = sim.step();
  record.time_s = sim.time_s();
  record.path = path.string();
  record.bytes = static_cast<std::int64_t>(std::filesystem::file_size(path, ec));
  record.attempt = job_.attempt;
  record.created_at_ms = NowMs();
  auto dropped = store_.RecordCheckpoint(job_.id, job_.lease_epoch, record, policy_.keep);
  if (!dropped.ok()) {
    if (dropped.status().code() == core::StatusCode::kAborted) return dropped.status();
    log_->warn("checkpoint at step {} not recorded: {}", sim.step(), dropped.status().ToString());
    return core::Status::Ok();
  }
  for (const CheckpointRecord& old : *dropped) {
    // The one just written may be among them (when stale newer records outrank it): keep it.
    if (old.step != record.step) std::filesystem::remove(old.path, ec);
  }
  ++written_;
  const double seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  seconds_writing_ += seconds;
  if (policy_.on_written) policy_.on_written(record.bytes, seconds);
  log_->debug("checkpoint at step {} ({} bytes)", record.step, record.bytes);
  return core::Status::Ok();
}

}  // namespace seep::service
