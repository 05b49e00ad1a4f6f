#include "rpc/worker_service.h"

#include <fmt/format.h>

#include <algorithm>
#include <optional>
#include <string>
#include <utility>

#include "codec/job_codec.h"
#include "codec/worker_codec.h"
#include "jobs/wall_clock.h"
#include "rpc/guarded_call.h"
#include "rpc/keep_lease_reactor.h"
#include "rpc/request_bounds.h"
#include "store/checkpoint_io.h"

namespace seep::service {
namespace {

constexpr std::uint32_t kMinLeaseMs = 500;
constexpr std::uint32_t kMaxLeaseMs = 86'400'000;
constexpr std::size_t kMaxEventKindBytes = 64;

core::Status CheckLeaseMs(std::uint32_t lease_ms) {
  if (lease_ms >= kMinLeaseMs && lease_ms <= kMaxLeaseMs) return core::Status::Ok();
  return core::InvalidArgument(
      fmt::format("lease_ms: must be {} .. {} (got {})", kMinLeaseMs, kMaxLeaseMs, lease_ms));
}

core::Status CheckLeaseRef(const v1::LeaseRef& lease, const char* field) {
  if (lease.job_id().empty()) {
    return core::InvalidArgument(fmt::format("{}.job_id: is required", field));
  }
  SEEP_RETURN_IF_ERROR(CheckIdLength(lease.job_id(), fmt::format("{}.job_id", field)));
  if (lease.lease_epoch() <= 0) {
    return core::InvalidArgument(
        fmt::format("{}.lease_epoch: must be > 0, the epoch ClaimJob returned (got {})", field,
                    lease.lease_epoch()));
  }
  return core::Status::Ok();
}

}  // namespace

WorkerServiceImpl::WorkerServiceImpl(JobStore& store, StoreLedger& ledger, JobHub& hub,
                                     std::shared_ptr<spdlog::logger> logger,
                                     WorkerServiceOptions options, ServiceMetrics* metrics)
    : store_(store),
      ledger_(ledger),
      hub_(hub),
      logger_(std::move(logger)),
      options_(options),
      metrics_(metrics) {}

template <typename Fn>
grpc::Status WorkerServiceImpl::Guarded(const grpc::ServerContext* ctx, const char* rpc,
                                        Fn&& fn) const {
  return GuardedCall(options_.auth, *logger_, metrics_, ctx, rpc, std::forward<Fn>(fn));
}

core::Result<JobRecord> WorkerServiceImpl::HeldJob(const v1::LeaseRef& lease, const char* field,
                                                   bool with_scene) {
  SEEP_RETURN_IF_ERROR(CheckLeaseRef(lease, field));
  auto job = with_scene ? store_.Get(lease.job_id()) : store_.GetWithoutScene(lease.job_id());
  if (!job.ok()) {
    if (job.status().code() == core::StatusCode::kNotFound) {
      return core::NotFound(
          fmt::format("{}.job_id: no job {} (deleted, or never submitted)", field, lease.job_id()));
    }
    return job.status();
  }
  if (job->state != JobState::kRunning || job->lease_epoch != lease.lease_epoch()) {
    return core::Aborted(fmt::format(
        "{}.lease_epoch: job {} is no longer running under lease epoch {} (it is {} under epoch "
        "{}); this worker must stop it without writing more",
        field, lease.job_id(), lease.lease_epoch(), JobStateName(job->state), job->lease_epoch));
  }
  return job;
}

core::Status WorkerServiceImpl::FencedWrite(const v1::LeaseRef& lease, const char* field,
                                            const std::function<core::Status()>& write) {
  SEEP_RETURN_IF_ERROR(CheckLeaseRef(lease, field));
  core::Status written = write();
  if (written.code() != core::StatusCode::kAborted) return written;
  // Refused: an unknown job, another epoch or a job no longer RUNNING; say which.
  const auto held = HeldJob(lease, field, /*with_scene=*/false);
  return held.ok() ? written : held.status();
}

grpc::Status WorkerServiceImpl::ClaimJob(Ctx* ctx, const v1::ClaimJobRequest* request,
                                         v1::ClaimJobResponse* response) {
  return Guarded(ctx, "ClaimJob", [&]() -> core::Status {
    if (request->worker().empty()) return core::InvalidArgument("worker: is required");
    SEEP_RETURN_IF_ERROR(CheckLeaseMs(request->lease_ms()));
    // Calibrations need the store's calibration records: seepd's own workers run them.
    std::optional<WorkerPlacement> placement;
    if (request->has_placement()) {
      const v1::BatchPlacement& where = request->placement();
      if (where.job_id().empty() || where.job_id().size() > 64) {
        return core::InvalidArgument(
            "placement.job_id: the batch system's job id is required with a placement (1 to 64 "
            "characters)");
      }
      if (where.node().size() > 256) {
        return core::InvalidArgument("placement.node: at most 256 characters");
      }
      placement = WorkerPlacement{where.job_id(), where.node()};
    }
    SEEP_ASSIGN_OR_RETURN(std::optional<JobRecord> claimed,
                          store_.ClaimNextQueued(request->worker(), NowMs(), request->lease_ms(),
                                                 JobKind::kSimulation, placement));
    if (!claimed) return core::Status::Ok();
    logger_->info(
        "job {} claimed by worker process {}{} (attempt {}, lease epoch {})", claimed->id,
        request->worker(),
        placement ? fmt::format(" in batch job {} on {}", placement->batch_job_id, placement->node)
                  : "",
        claimed->attempt, claimed->lease_epoch);
    {
      std::lock_guard lock(counted_mutex_);
      counted_steps_[claimed->id] = claimed->progress.step;
    }
    hub_.RecordChanged(claimed->id);  // QUEUED -> RUNNING, for its followers
    hub_.Publish(claimed->id, claimed->progress);
    LeasedJobToProto(*claimed, response->mutable_job());
    return core::Status::Ok();
  });
}

core::Result<bool> WorkerServiceImpl::Renew(const v1::LeaseRef& lease, std::uint32_t lease_ms) {
  SEEP_RETURN_IF_ERROR(CheckLeaseMs(lease_ms));
  bool cancel = false;
  SEEP_RETURN_IF_ERROR(FencedWrite(lease, "lease", [&]() -> core::Status {
    SEEP_ASSIGN_OR_RETURN(cancel, ledger_.Heartbeat(lease.job_id(), lease.lease_epoch(),
                                                    std::chrono::milliseconds(lease_ms)));
    return core::Status::Ok();
  }));
  return cancel;
}

core::Status WorkerServiceImpl::StoreProgress(const v1::LeaseRef& lease,
                                              const v1::Progress& message) {
  const JobProgress progress = ProgressFromProto(message);
  SEEP_RETURN_IF_ERROR(FencedWrite(lease, "lease", [&] {
    return ledger_.UpdateProgress(lease.job_id(), lease.lease_epoch(), progress);
  }));
  hub_.Publish(lease.job_id(), progress);
  CountSteps(lease.job_id(), progress.step);
  return core::Status::Ok();
}

void WorkerServiceImpl::CountSteps(const std::string& id, std::uint64_t step) {
  if (metrics_ == nullptr) return;
  std::lock_guard lock(counted_mutex_);
  const auto it = counted_steps_.find(id);
  if (it == counted_steps_.end() || step <= it->second) return;
  metrics_->AddSteps(step - it->second);
  it->second = step;
}

grpc::Status WorkerServiceImpl::Heartbeat(Ctx* ctx, const v1::HeartbeatRequest* request,
                                          v1::HeartbeatResponse* response) {
  return Guarded(ctx, "Heartbeat", [&]() -> core::Status {
    SEEP_ASSIGN_OR_RETURN(const bool cancel, Renew(request->lease(), request->lease_ms()));
    response->set_cancel_requested(cancel);
    return core::Status::Ok();
  });
}

grpc::Status WorkerServiceImpl::ReportProgress(Ctx* ctx, const v1::ReportProgressRequest* request,
                                               v1::ReportProgressResponse*) {
  return Guarded(ctx, "ReportProgress",
                 [&] { return StoreProgress(request->lease(), request->progress()); });
}

core::Result<bool> WorkerServiceImpl::Beat(const v1::LeaseBeat& beat) {
  if (beat.lease_ms() == 0 && !beat.has_progress()) {
    return core::InvalidArgument(
        fmt::format("lease_ms: a beat without progress renews the lease: {} .. {} ms (got 0)",
                    kMinLeaseMs, kMaxLeaseMs));
  }
  bool cancel = false;
  if (beat.lease_ms() != 0) {
    SEEP_ASSIGN_OR_RETURN(cancel, Renew(beat.lease(), beat.lease_ms()));
  }
  if (beat.has_progress()) SEEP_RETURN_IF_ERROR(StoreProgress(beat.lease(), beat.progress()));
  return cancel;
}

grpc::ServerBidiReactor<v1::LeaseBeat, v1::LeaseNews>* WorkerServiceImpl::KeepLease(
    grpc::CallbackServerContext* ctx) {
  return new KeepLeaseReactor(
      ctx, options_.auth, [this](const v1::LeaseBeat& beat) { return Beat(beat); }, *logger_,
      metrics_);
}

grpc::Status WorkerServiceImpl::AddJobEvent(Ctx* ctx, const v1::AddJobEventRequest* request,
                                            v1::AddJobEventResponse*) {
  return Guarded(ctx, "AddJobEvent", [&]() -> core::Status {
    if (request->kind().empty() || request->kind().size() > kMaxEventKindBytes) {
      return core::InvalidArgument(fmt::format("kind: must be 1 .. {} characters (got {})",
                                               kMaxEventKindBytes, request->kind().size()));
    }
    return FencedWrite(request->lease(), "lease", [&] {
      return ledger_.AddEvent(request->lease().job_id(), request->lease().lease_epoch(),
                              request->kind(), request->message());
    });
  });
}

grpc::Status WorkerServiceImpl::UploadCheckpoint(
    Ctx* ctx, grpc::ServerReader<v1::UploadCheckpointRequest>* reader,
    v1::UploadCheckpointResponse* response) {
  return Guarded(ctx, "UploadCheckpoint", [&]() -> grpc::Status {
    v1::UploadCheckpointRequest first;
    if (!reader->Read(&first) || !first.has_start()) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              "start: the first message of an upload must be its start (lease, step, size, "
              "SHA-256); nothing kept"};
    }
    return ReceiveCheckpoint(*reader, first.start(), response);
  });
}

grpc::Status WorkerServiceImpl::ReceiveCheckpoint(
    grpc::ServerReader<v1::UploadCheckpointRequest>& reader, const v1::CheckpointUploadStart& start,
    v1::UploadCheckpointResponse* response) {
  if (start.state_bytes() > options_.max_checkpoint_bytes) {
    return {grpc::StatusCode::RESOURCE_EXHAUSTED,
            fmt::format("start.state_bytes: a checkpoint of {} bytes is over the limit of {} "
                        "bytes (seepd --max-checkpoint-bytes); nothing kept",
                        start.state_bytes(), options_.max_checkpoint_bytes)};
  }
  if (start.state_sha256().size() != 32) {
    return ToGrpcStatus(core::InvalidArgument(
        fmt::format("start.state_sha256: must be the 32 bytes of a SHA-256 (got {})",
                    start.state_sha256().size())));
  }
  if (start.keep() < 1 || start.keep() > 1000) {
    return ToGrpcStatus(
        core::InvalidArgument(fmt::format("start.keep: must be 1 .. 1000 (got {})", start.keep())));
  }
  auto held = HeldJob(start.lease(), "start.lease", /*with_scene=*/true);
  if (!held.ok()) return ToGrpcStatus(held.status());
  // Gathered in memory and kept only once whole: a broken or short upload leaves nothing, and
  // the file is then written as a local worker's is (temporary file, fsync, rename).
  std::string state;
  v1::UploadCheckpointRequest message;
  std::uint32_t expected_index = 0;
  while (reader.Read(&message)) {
    if (!message.has_chunk()) {
      return ToGrpcStatus(core::InvalidArgument(fmt::format(
          "chunk[{}]: expected a chunk after the start, got another start; nothing kept",
          expected_index)));
    }
    const v1::CheckpointPiece& chunk = message.chunk();
    if (chunk.index() != expected_index) {
      return ToGrpcStatus(core::InvalidArgument(
          fmt::format("chunk[{}].index: chunks come in order from 0, expected {} (got {}); "
                      "nothing kept",
                      expected_index, expected_index, chunk.index())));
    }
    if (chunk.payload().size() > kCheckpointChunkBytes) {
      return ToGrpcStatus(core::InvalidArgument(
          fmt::format("chunk[{}].payload: at most {} bytes per chunk (got {}); nothing kept",
                      chunk.index(), kCheckpointChunkBytes, chunk.payload().size())));
    }
    if (state.size() + chunk.payload().size() > start.state_bytes()) {
      return ToGrpcStatus(core::InvalidArgument(
          fmt::format("chunk[{}].payload: the chunks exceed start.state_bytes = {}; nothing kept",
                      chunk.index(), start.state_bytes())));
    }
    state += chunk.payload();
    ++expected_index;
  }
  if (state.size() != start.state_bytes()) {
    return ToGrpcStatus(core::InvalidArgument(
        fmt::format("start.state_bytes: the upload ended after {} of {} bytes; nothing kept",
                    state.size(), start.state_bytes())));
  }
  if (Sha256(state) != start.state_sha256()) {
    return ToGrpcStatus(core::DataLoss(
        "start.state_sha256: the bytes received do not have this SHA-256 (damaged in transit); "
        "nothing kept"));
  }
  JobRecord& job = *held;
  CheckpointMeta meta;
  meta.build_id = start.build_id();
  meta.job_id = job.id;
  meta.scene_sha256 = Sha256(job.scene);  // the stored scene's, not the worker's word for it
  meta.scene = job.scene;
  meta.step = start.step();
  meta.time_s = start.time_s();
  const auto writing = std::chrono::steady_clock::now();
  auto kept = ledger_.SaveCheckpoint(job, meta, state, start.keep(), CheckpointRole::kResumePoint);
  if (!kept.ok()) return ToGrpcStatus(kept.status());
  if (metrics_ != nullptr) {
    metrics_->RecordCheckpoint(
        *kept, std::chrono::duration<double>(std::chrono::steady_clock::now() - writing).count());
  }
  response->set_file_bytes(*kept);
  return grpc::Status::OK;
}

grpc::Status WorkerServiceImpl::DownloadCheckpoint(
    Ctx* ctx, const v1::DownloadCheckpointRequest* request,
    grpc::ServerWriter<v1::DownloadCheckpointResponse>* writer) {
  return Guarded(ctx, "DownloadCheckpoint", [&]() -> core::Status {
    SEEP_ASSIGN_OR_RETURN(const JobRecord job, HeldJob(request->lease(), "lease", true));
    std::optional<std::uint64_t> below;
    if (request->has_below_step()) below = request->below_step();
    SEEP_ASSIGN_OR_RETURN(const std::optional<FetchedCheckpoint> fetched,
                          ledger_.NewestCheckpoint(job, below));
    v1::DownloadCheckpointResponse head;
    v1::CheckpointDownloadStart* start = head.mutable_start();
    start->set_found(fetched.has_value());
    if (fetched) {
      start->set_step(fetched->step);
      start->set_name(fetched->name);
      start->set_build_id(fetched->meta.build_id);
      start->set_header_step(fetched->meta.step);
      start->set_time_s(fetched->meta.time_s);
      start->set_state_bytes(fetched->state.size());
      start->set_state_sha256(Sha256(fetched->state));
    }
    if (!writer->Write(head)) return core::Unavailable("the worker went away");
    if (!fetched) return core::Status::Ok();
    std::uint32_t index = 0;
    for (std::size_t at = 0; at < fetched->state.size(); at += kCheckpointChunkBytes, ++index) {
      v1::DownloadCheckpointResponse piece;
      piece.mutable_chunk()->set_index(index);
      piece.mutable_chunk()->set_payload(fetched->state.substr(at, kCheckpointChunkBytes));
      if (!writer->Write(piece)) return core::Unavailable("the worker went away");
    }
    return core::Status::Ok();
  });
}

grpc::Status WorkerServiceImpl::StoreResultSeries(Ctx* ctx,
                                                  const v1::StoreResultSeriesRequest* request,
                                                  v1::StoreResultSeriesResponse*) {
  return Guarded(ctx, "StoreResultSeries", [&]() -> core::Status {
    if (request->state_sha256().size() != 64) {
      return core::InvalidArgument(
          fmt::format("state_sha256: must be 64 hex digits (got {} characters)",
                      request->state_sha256().size()));
    }
    if (!request->columns().empty() && request->values_size() % request->columns_size() != 0) {
      return core::InvalidArgument(
          fmt::format("values: {} values do not make whole rows of {} columns",
                      request->values_size(), request->columns_size()));
    }
    const std::vector<std::string> columns(request->columns().begin(), request->columns().end());
    const std::vector<double> values(request->values().begin(), request->values().end());
    // A worker that sends none (an older one) gave its final progress as a beat.
    std::optional<JobProgress> final_progress;
    if (request->has_final_progress()) {
      final_progress = ProgressFromProto(request->final_progress());
    }
    SEEP_RETURN_IF_ERROR(FencedWrite(request->lease(), "lease", [&] {
      return store_.StoreResultSeries(request->lease().job_id(), request->lease().lease_epoch(),
                                      columns, values, request->state_sha256(),
                                      final_progress ? &*final_progress : nullptr);
    }));
    if (final_progress) CountSteps(request->lease().job_id(), final_progress->step);
    return core::Status::Ok();
  });
}

grpc::Status WorkerServiceImpl::FinishJob(Ctx* ctx, const v1::FinishJobRequest* request,
                                          v1::FinishJobResponse*) {
  return Guarded(ctx, "FinishJob", [&]() -> core::Status {
    const std::optional<JobState> state = JobStateFromProto(request->state());
    if (!state || !IsTerminal(*state)) {
      return core::InvalidArgument(
          fmt::format("state: must be JOB_STATE_SUCCEEDED, _FAILED or _CANCELLED (got {})",
                      v1::JobState_Name(request->state())));
    }
    std::vector<std::pair<std::string, double>> metrics;
    metrics.reserve(request->metrics_size());
    for (const v1::NamedValue& m : request->metrics()) metrics.emplace_back(m.name(), m.value());
    const std::string& id = request->lease().job_id();
    SEEP_RETURN_IF_ERROR(FencedWrite(request->lease(), "lease", [&] {
      return ledger_.Finish(id, request->lease().lease_epoch(), *state, request->error_code(),
                            request->error_message(), metrics, request->wall_time_s());
    }));
    logger_->info("job {} {} in a worker process after {:.3f} s", id, JobStateName(*state),
                  request->wall_time_s());
    {
      std::lock_guard lock(counted_mutex_);
      counted_steps_.erase(id);
    }
    hub_.Finished(id);
    return core::Status::Ok();
  });
}

grpc::Status WorkerServiceImpl::ReturnJob(Ctx* ctx, const v1::ReturnJobRequest* request,
                                          v1::ReturnJobResponse*) {
  return Guarded(ctx, "ReturnJob", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(HeldJob(request->lease(), "lease", false).status());
    // The lease ends now; the rescuer's next round queues the job again (not a release without
    // expiry, which only seepd's own next start would undo).
    SEEP_ASSIGN_OR_RETURN(
        const bool cancel,
        store_.Heartbeat(request->lease().job_id(), request->lease().lease_epoch(), NowMs()));
    logger_->info("job {} given back by its remote worker (lease epoch {}){}",
                  request->lease().job_id(), request->lease().lease_epoch(),
                  cancel ? "; a cancel is pending" : "");
    return core::Status::Ok();
  });
}

}  // namespace seep::service
