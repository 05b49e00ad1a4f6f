#include "jobs/newest_checkpoint.h"

#include "codec/simulation_state_codec.h"

namespace seep::service {

std::optional<RestoredCheckpoint> LoadNewestCheckpoint(
    const JobRecord& job, std::span<const CheckpointRecord> newest_first, core::Simulation& sim,
    const std::function<void(const SkippedCheckpoint&)>& on_skip) {
  const std::string scene_sha256 = Sha256(job.scene);
  for (const CheckpointRecord& record : newest_first) {
    auto file = ReadCheckpointFile(record.path);
    if (!file.ok()) {
      on_skip({record, file.status()});
      continue;
    }
    if (file->meta.job_id != job.id || file->meta.scene_sha256 != scene_sha256) {
      on_skip({record, core::DataLoss("belongs to another job or scene"), /*foreign=*/true});
      continue;
    }
    auto snapshot = ParseSimulationState(file->state);
    if (!snapshot.ok()) {
      on_skip({record, snapshot.status()});
      continue;
    }
    if (core::Status restored = sim.Restore(*snapshot); !restored.ok()) {
      on_skip({record, restored});
      continue;
    }
    return RestoredCheckpoint{record, std::move(file->meta)};
  }
  return std::nullopt;
}

}  // namespace seep::service
