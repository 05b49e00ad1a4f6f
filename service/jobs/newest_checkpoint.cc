#include "jobs/newest_checkpoint.h"

#include "codec/simulation_state_codec.h"

namespace seep::service {

std::optional<VerifiedCheckpoint> NextVerifiedCheckpoint(
    const JobRecord& job, std::span<const CheckpointRecord> newest_first,
    std::optional<std::uint64_t> below_step,
    const std::function<void(const SkippedCheckpoint&)>& on_skip) {
  const std::string scene_sha256 = Sha256(job.scene);
  for (const CheckpointRecord& record : newest_first) {
    if (below_step && record.step >= *below_step) continue;
    auto file = ReadCheckpoint(record);
    if (!file.ok()) {
      on_skip({record, file.status()});
      continue;
    }
    if (file->meta.job_id != job.id || file->meta.scene_sha256 != scene_sha256) {
      on_skip({record, core::DataLoss("belongs to another job or scene"), /*foreign=*/true});
      continue;
    }
    return VerifiedCheckpoint{record, std::move(*file)};
  }
  return std::nullopt;
}

std::optional<RestoredCheckpoint> LoadNewestCheckpoint(
    const JobRecord& job, std::span<const CheckpointRecord> newest_first, core::Simulation& sim,
    const std::function<void(const SkippedCheckpoint&)>& on_skip) {
  std::optional<std::uint64_t> below;
  while (auto verified = NextVerifiedCheckpoint(job, newest_first, below, on_skip)) {
    below = verified->record.step;
    auto snapshot = ParseSimulationState(verified->file.state);
    if (!snapshot.ok()) {
      on_skip({verified->record, snapshot.status()});
      continue;
    }
    if (core::Status restored = sim.Restore(*snapshot); !restored.ok()) {
      on_skip({verified->record, restored});
      continue;
    }
    return RestoredCheckpoint{verified->record, std::move(verified->file.meta)};
  }
  return std::nullopt;
}

}  // namespace seep::service
