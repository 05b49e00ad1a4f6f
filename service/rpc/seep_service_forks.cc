// SeepServiceImpl: the fork half of SubmitJob (SubmitJobRequest.from_job_id). The parent's
// checkpoint is chosen and verified, the fork's scene compared with the parent's, and the
// checkpoint copied under the fork's id with a header naming the fork and its scene; the store
// then records the fork with that copy as its first checkpoint, so the runner's usual resume
// starts it there, whatever later happens to the parent. Nothing is kept on an error.
#include <fmt/format.h>

#include <algorithm>
#include <system_error>

#include "codec/fork_scene.h"
#include "jobs/wall_clock.h"
#include "rpc/handler.h"
#include "rpc/seep_service.h"
#include "seep/v1/checkpoint.pb.h"
#include "store/checkpoint_io.h"
#include "store/durable_files.h"

namespace seep::service {
namespace {

// At most this many steps are listed when a from_step matches none.
constexpr std::size_t kListedSteps = 10;

// "100, 200, 300", ascending; the newest kListedSteps of them when there are more.
std::string ListSteps(const std::vector<CheckpointRecord>& newest_first) {
  std::vector<std::uint64_t> steps;
  for (const CheckpointRecord& r : newest_first) {
    if (steps.size() == kListedSteps) break;
    steps.push_back(r.step);
  }
  std::reverse(steps.begin(), steps.end());
  std::string out = newest_first.size() > steps.size()
                        ? fmt::format("({} in all; the newest) ", newest_first.size())
                        : std::string();
  for (std::size_t i = 0; i < steps.size(); ++i)
    out += fmt::format("{}{}", i ? ", " : "", steps[i]);
  return out;
}

// The parent's checkpoint as read and verified: its header, its state bytes and the stage the
// state is in.
struct ParentCheckpoint {
  const CheckpointRecord* record = nullptr;
  CheckpointFile file;
  std::uint32_t stage_index = 0;
};

// Reads one of the parent's checkpoint files and checks that it is the parent's, of its scene,
// with a staged run's state in it.
core::Result<ParentCheckpoint> ReadParentCheckpoint(const JobRecord& parent,
                                                    const CheckpointRecord& record) {
  SEEP_ASSIGN_OR_RETURN(CheckpointFile file, ReadCheckpoint(record));
  if (file.meta.job_id != parent.id || file.meta.scene_sha256 != Sha256(parent.scene)) {
    return core::DataLoss("it belongs to another job or scene");
  }
  v1::SimulationState state;
  if (!state.ParseFromString(file.state) || !state.has_stages()) {
    return core::DataLoss("its state does not parse as a staged run's");
  }
  const std::uint32_t stage_index = state.stages().index();
  return ParentCheckpoint{&record, std::move(file), stage_index};
}

// The checkpoint the fork starts from: the one at from_step, or the newest that verifies.
core::Result<ParentCheckpoint> ChooseParentCheckpoint(const JobRecord& parent,
                                                      const std::vector<CheckpointRecord>& records,
                                                      std::optional<std::uint64_t> from_step) {
  if (records.empty()) {
    return core::InvalidArgument(
        fmt::format("from_job_id: job {} has no checkpoint yet (it is {}); fork it once it has "
                    "written one",
                    parent.id, JobStateName(parent.state)));
  }
  if (from_step) {
    const auto it = std::find_if(records.begin(), records.end(),
                                 [&](const CheckpointRecord& r) { return r.step == *from_step; });
    if (it == records.end()) {
      return core::InvalidArgument(
          fmt::format("from_step: job {} has no checkpoint at step {}; its checkpoints are at "
                      "steps {}",
                      parent.id, *from_step, ListSteps(records)));
    }
    auto chosen = ReadParentCheckpoint(parent, *it);
    if (!chosen.ok()) {
      return core::DataLoss(fmt::format(
          "from_step: job {}'s checkpoint at step {} cannot be used: {}; its checkpoints are at "
          "steps {}",
          parent.id, *from_step, chosen.status().message(), ListSteps(records)));
    }
    return chosen;
  }
  std::string newest_failure;
  for (const CheckpointRecord& record : records) {
    auto chosen = ReadParentCheckpoint(parent, record);
    if (chosen.ok()) return chosen;
    if (newest_failure.empty()) {
      newest_failure = fmt::format("step {}: {}", record.step, chosen.status().message());
    }
  }
  return core::DataLoss(
      fmt::format("from_job_id: none of job {}'s {} checkpoint(s) can be used "
                  "(the newest, {})",
                  parent.id, records.size(), newest_failure));
}

}  // namespace

core::Result<SeepServiceImpl::ForkStart> SeepServiceImpl::PrepareFork(
    const v1::SubmitJobRequest& request, const JobRecord& fork) {
  const std::string& parent_id = request.from_job_id();
  auto parent = store_.Get(parent_id);
  if (!parent.ok()) {
    if (parent.status().code() != core::StatusCode::kNotFound) return parent.status();
    return core::NotFound(fmt::format("from_job_id: job {} not found", parent_id));
  }
  if (parent->kind == JobKind::kCalibration) {
    return core::InvalidArgument(
        fmt::format("from_job_id: job {} is a calibration; a fork continues a simulation job's run",
                    parent_id));
  }
  v1::Scene parent_scene;
  if (!parent_scene.ParseFromString(parent->scene)) {
    return core::DataLoss(
        fmt::format("from_job_id: job {}'s stored scene does not parse", parent_id));
  }
  if (parent_scene.stages_size() == 0) {
    return core::InvalidArgument(fmt::format(
        "from_job_id: job {}'s scene has no stages; a fork continues a staged run with stages of "
        "its own",
        parent_id));
  }
  SEEP_ASSIGN_OR_RETURN(const std::vector<CheckpointRecord> records,
                        store_.ListCheckpoints(parent_id));
  const std::optional<std::uint64_t> from_step =
      request.has_from_step() ? std::optional<std::uint64_t>(request.from_step()) : std::nullopt;
  SEEP_ASSIGN_OR_RETURN(ParentCheckpoint chosen,
                        ChooseParentCheckpoint(*parent, records, from_step));
  SEEP_RETURN_IF_ERROR(CheckForkScene(parent_scene, request.scene(),
                                      {parent_id, chosen.record->step, chosen.stage_index}));

  // The copy: the same state (and the build that wrote it), headed for the fork and its scene,
  // where the fork's own checkpoints go.
  std::error_code ec;
  const std::filesystem::path dir = store_.data_dir() / "checkpoints" / fork.id;
  const std::filesystem::path path = dir / fmt::format("ckpt-{:012}.bin", chosen.record->step);
  CheckpointMeta meta = chosen.file.meta;
  meta.job_id = fork.id;
  meta.scene_sha256 = Sha256(fork.scene);
  meta.scene = fork.scene;
  meta.format_version = kCheckpointFormatVersion;  // the copy is written by this build
  SEEP_RETURN_IF_ERROR(store_.free_space().CheckRoom(kNoNewJobs, chosen.file.state.size()));
  core::Status copied = CreateDirectoriesDurably(dir);
  if (copied.ok()) copied = WriteCheckpointFile(path, meta, chosen.file.state);
  if (!copied.ok()) {
    RemoveForkCopy(path);
    return core::Status(
        copied.code(),
        fmt::format("from_job_id: job {}'s checkpoint at step {} could not be "
                    "copied for the fork: {}",
                    parent_id, chosen.record->step, HideDataFolder(copied.message(), path)));
  }
  ForkStart start;
  start.parent_job_id = parent_id;
  start.checkpoint.step = chosen.record->step;
  start.checkpoint.time_s = meta.time_s;
  start.checkpoint.path = path.string();
  start.checkpoint.bytes = static_cast<std::int64_t>(std::filesystem::file_size(path, ec));
  start.checkpoint.attempt = 1;
  start.checkpoint.created_at_ms = NowMs();
  return start;
}

void SeepServiceImpl::RemoveForkCopy(const std::filesystem::path& path) {
  for (const std::filesystem::path& p : {path, path.parent_path()}) {
    if (core::Status s = RemoveDurably(p); !s.ok()) {
      // Left to the start-up sweep, which removes every file no record points to.
      logger_->warn("fork: {} not removed: {}", p.string(), s.ToString());
    }
  }
}

core::Result<InsertOutcome> SeepServiceImpl::InsertFork(const v1::SubmitJobRequest& request,
                                                        JobRecord& fork) {
  SEEP_ASSIGN_OR_RETURN(const ForkStart start, PrepareFork(request, fork));
  fork.parent_job_id = start.parent_job_id;
  fork.parent_step = start.checkpoint.step;
  auto outcome = store_.InsertFork(fork, start.checkpoint);
  // Not stored, or the request_id's job was returned: its copy is not needed.
  if (!outcome.ok() || !outcome->created) RemoveForkCopy(start.checkpoint.path);
  return outcome;
}

}  // namespace seep::service
