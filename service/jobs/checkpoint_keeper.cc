#include "jobs/checkpoint_keeper.h"

#include <fmt/format.h>

#include "codec/simulation_state_codec.h"
#include "jobs/wall_clock.h"

namespace seep::service {
CheckpointKeeper::CheckpointKeeper(JobLedger& ledger, const CheckpointPolicy& policy,
                                   const JobRecord& job, std::string build_id,
                                   std::shared_ptr<spdlog::logger> log)
    : ledger_(ledger),
      policy_(policy),
      job_(job),
      build_id_(std::move(build_id)),
      scene_sha256_(Sha256(job.scene)),
      log_(std::move(log)),
      last_time_(std::chrono::steady_clock::now()) {}

void CheckpointKeeper::Event(const std::string& kind, const std::string& message) {
  if (auto s = ledger_.AddEvent(job_.id, job_.lease_epoch, kind, message); !s.ok()) {
    log_->warn("event not stored: {}", s.ToString());
  }
}

std::optional<std::uint64_t> CheckpointKeeper::RestoreNewest(core::Simulation& sim) {
  std::optional<std::uint64_t> below;
  for (;;) {
    auto fetched = ledger_.NewestCheckpoint(job_, below);
    if (!fetched.ok()) {
      log_->warn("checkpoints not fetched ({}); starting from the beginning",
                 fetched.status().ToString());
      return std::nullopt;
    }
    if (!*fetched) return std::nullopt;
    const FetchedCheckpoint& checkpoint = **fetched;
    below = checkpoint.step;
    auto snapshot = ParseSimulationState(checkpoint.state);
    const core::Status restored = snapshot.ok() ? sim.Restore(*snapshot) : snapshot.status();
    if (!restored.ok()) {
      log_->warn("checkpoint {} (step {}) skipped: {}", checkpoint.name, checkpoint.step,
                 restored.ToString());
      Event("CHECKPOINT_SKIPPED",
            fmt::format("{} (step {}): {}", checkpoint.name, checkpoint.step, restored.ToString()));
      continue;
    }
    if (checkpoint.meta.build_id != build_id_) {
      const std::string note = fmt::format(
          "checkpoint written by build {}, continued by build {}: bit-identity with an "
          "uninterrupted run is promised only for the same build",
          checkpoint.meta.build_id, build_id_);
      log_->warn("{}", note);
      Event("BUILD_CHANGED", note);
    }
    last_step_ = sim.step();
    last_time_ = std::chrono::steady_clock::now();
    log_->info("resumed from checkpoint {} at step {} (t = {} s)", checkpoint.name, sim.step(),
               sim.time_s());
    Event("RESUMED",
          fmt::format("from {} at step {} of {}", checkpoint.name, sim.step(), sim.total_steps()));
    return sim.step();
  }
}

core::Status CheckpointKeeper::MaybeWrite(const core::Simulation& sim) {
  if (!enabled() || sim.finished()) return core::Status::Ok();  // the end writes its own
  const bool by_steps = policy_.every_steps > 0 && sim.step() - last_step_ >= policy_.every_steps;
  // Coarse (a tick late at most): this runs at every step.
  const bool by_time =
      policy_.interval.count() > 0 && CoarseSteadyNow() - last_time_ >= policy_.interval;
  if (!by_steps && !by_time) return core::Status::Ok();
  return Write(sim);
}

core::Status CheckpointKeeper::Write(const core::Simulation& sim) {
  if (!enabled()) return core::Status::Ok();
  const auto start = std::chrono::steady_clock::now();
  last_step_ = sim.step();
  last_time_ = start;
  auto saved =
      ledger_.SaveCheckpoint(job_, MetaOf(sim), SerializeSimulationState(sim.TakeSnapshot()),
                             policy_.keep, CheckpointRole::kResumePoint);
  if (!saved.ok()) {
    if (saved.status().code() == core::StatusCode::kAborted) return saved.status();
    log_->warn("checkpoint at step {} not kept: {}", sim.step(), saved.status().ToString());
    Event("CHECKPOINT_FAILED", fmt::format("step {}: {}", sim.step(), saved.status().ToString()));
    // A full disk stops the run (a run that went on would keep no checkpoint at all); any other
    // failure leaves it running, less protected.
    if (saved.status().code() == core::StatusCode::kResourceExhausted) return saved.status();
    return core::Status::Ok();
  }
  CountWritten(*saved,
               std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count());
  log_->debug("checkpoint at step {} ({} bytes)", sim.step(), *saved);
  return core::Status::Ok();
}

std::optional<FinalState> CheckpointKeeper::FinalStateOf(const core::Simulation& sim,
                                                         std::string_view state) const {
  if (!enabled()) return std::nullopt;
  return FinalState{MetaOf(sim), state, policy_.keep};
}

void CheckpointKeeper::CountFinalState(const FinalState& final_state, const FinalStateKept& kept,
                                       double seconds) {
  if (kept.bytes) {
    CountWritten(*kept.bytes, seconds);
  } else if (!kept.failure.ok()) {  // its CHECKPOINT_FAILED event is the ledger's
    log_->warn("final state at step {} not kept: {}", final_state.meta.step,
               kept.failure.ToString());
  }
}

CheckpointMeta CheckpointKeeper::MetaOf(const core::Simulation& sim) const {
  CheckpointMeta meta;
  meta.build_id = build_id_;
  meta.job_id = job_.id;
  meta.scene_sha256 = scene_sha256_;
  meta.scene = job_.scene;
  meta.step = sim.step();
  meta.time_s = sim.time_s();
  return meta;
}

void CheckpointKeeper::CountWritten(std::int64_t bytes, double seconds) {
  ++written_;
  seconds_writing_ += seconds;
  if (policy_.on_written) policy_.on_written(bytes, seconds);
}

}  // namespace seep::service
