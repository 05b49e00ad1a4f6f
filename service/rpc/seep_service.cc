#include "rpc/seep_service.h"

#include <fmt/format.h>

#include <chrono>

#include "codec/job_codec.h"
#include "codec/scene_codec.h"
#include "codec/state_size_estimate.h"
#include "jobs/secure_random.h"
#include "jobs/wall_clock.h"
#include "rpc/handler.h"
#include "rpc/held_reason.h"
#include "rpc/job_labels.h"
#include "rpc/page_token.h"

namespace seep::service {
namespace {

constexpr std::size_t kMaxRequestIdLength = 200;
// The range of SubmitJobRequest.priority.
constexpr std::int32_t kMinPriority = -1000;
constexpr std::int32_t kMaxPriority = 1000;
constexpr std::size_t kMaxNameFilterLength = 200;
// ListJobs' states and kinds: each value once is a handful; more is no filter anyone means.
constexpr int kMaxFilterValues = 16;

}  // namespace

// Job and sweep ids are random, not sequential, so that two servers' ids never collide when
// records are merged, and from the kernel's cryptographic generator so that one id says nothing
// of the next; 64 bits of entropy.
core::Result<std::string> NewRandomId(char prefix) {
  SEEP_ASSIGN_OR_RETURN(const std::uint64_t bits, SecureRandomU64());
  return fmt::format("{}-{:016x}", prefix, bits);
}

core::Status CheckRequestId(const std::string& request_id) {
  if (request_id.size() <= kMaxRequestIdLength) return core::Status::Ok();
  return core::InvalidArgument(
      fmt::format("request_id: at most {} characters", kMaxRequestIdLength));
}

core::Status CheckPriority(std::int32_t priority) {
  if (priority >= kMinPriority && priority <= kMaxPriority) return core::Status::Ok();
  return core::InvalidArgument(fmt::format("priority: must be between {} and {} (got {})",
                                           kMinPriority, kMaxPriority, priority));
}

SeepServiceImpl::SeepServiceImpl(JobStore& store, JobHub& hub, PhysicsPool& physics,
                                 std::string build_id, ServiceHooks hooks,
                                 std::shared_ptr<spdlog::logger> logger, ServiceGuards guards,
                                 ServiceMetrics* metrics)
    : store_(store),
      hub_(hub),
      physics_(physics),
      build_id_(std::move(build_id)),
      hooks_(std::move(hooks)),
      logger_(std::move(logger)),
      guards_(guards),
      metrics_(metrics) {}

core::Result<JobRecord> SeepServiceImpl::LoadJob(const std::string& id, bool with_scene) {
  SEEP_ASSIGN_OR_RETURN(JobRecord job, with_scene ? store_.Get(id) : store_.GetWithoutScene(id));
  if (job.state == JobState::kRunning) {
    if (auto live = hub_.Live(id)) job.progress = *live;
  }
  return job;
}

grpc::Status SeepServiceImpl::SubmitJob(grpc::ServerContext* ctx, const v1::SubmitJobRequest* req,
                                        v1::SubmitJobResponse* resp) {
  return Guarded(ctx, "SubmitJob", [&]() -> core::Status {
    if (req->has_scene() && req->has_calibration()) {
      return core::InvalidArgument(
          "calibration: set either scene (a simulation) or calibration, not both");
    }
    if (!req->has_scene() && !req->has_calibration()) {
      return core::InvalidArgument("scene: is required");
    }
    if (req->from_job_id().empty() && req->has_from_step()) {
      return core::InvalidArgument("from_step: only with from_job_id (the job to fork)");
    }
    if (!req->from_job_id().empty() && req->has_calibration()) {
      return core::InvalidArgument(
          "from_job_id: a fork continues a simulation's run; send its scene, not a calibration");
    }
    SEEP_RETURN_IF_ERROR(CheckIdLength(req->from_job_id(), "from_job_id"));
    SEEP_RETURN_IF_ERROR(CheckRequestId(req->request_id()));
    SEEP_RETURN_IF_ERROR(CheckPriority(req->priority()));
    JobRecord job;
    SEEP_ASSIGN_OR_RETURN(job.labels, CheckLabels(req->labels()));
    SEEP_ASSIGN_OR_RETURN(job.id, NewRandomId('j'));
    job.priority = req->priority();
    if (req->has_calibration()) {
      // seep_service_calibrations.cc: checks, from_job_id, validation, serialization.
      SEEP_ASSIGN_OR_RETURN(PreparedCalibration prepared,
                            PrepareCalibrationJob(req->calibration()));
      job.kind = JobKind::kCalibration;
      job.name = prepared.name.empty() ? job.id : prepared.name;
      job.scene = std::move(prepared.bytes);
    } else {
      SEEP_ASSIGN_OR_RETURN(job.scene, PrepareSimulationJob(req->scene()));
      job.name = req->scene().name().empty() ? job.id : req->scene().name();
    }
    if (!req->request_id().empty()) job.request_id = req->request_id();
    job.build_id = build_id_;
    job.created_at_ms = NowMs();
    SEEP_ASSIGN_OR_RETURN(const InsertOutcome outcome,
                          req->from_job_id().empty() ? store_.Insert(job) : InsertFork(*req, job));
    if (outcome.created) {
      logger_->info("{} job {} submitted ('{}'){}",
                    outcome.job.kind == JobKind::kCalibration ? "calibration" : "simulation",
                    outcome.job.id, outcome.job.name,
                    outcome.job.parent_job_id
                        ? fmt::format(", forked from job {} at step {}", *outcome.job.parent_job_id,
                                      outcome.job.parent_step)
                        : std::string());
      if (hooks_.wake_workers) hooks_.wake_workers();
    }
    SEEP_ASSIGN_OR_RETURN(const JobRecord current, LoadJob(outcome.job.id));
    JobToProto(current, /*with_scene=*/true, resp->mutable_job());
    resp->set_created(outcome.created);
    return core::Status::Ok();
  });
}

core::Result<std::string> SeepServiceImpl::PrepareSimulationJob(const v1::Scene& scene) {
  SEEP_RETURN_IF_ERROR(CheckNameLength(scene.name(), "scene.name"));
  // Measured before decoding, so an oversized scene costs no decode and leaves no trace.
  if (const std::size_t bytes = scene.ByteSizeLong(); bytes > guards_.max_scene_bytes) {
    return core::InvalidArgument(
        fmt::format("scene: {} bytes exceed the limit of {} (seepd --max-scene-bytes)", bytes,
                    guards_.max_scene_bytes));
  }
  // Decoded and validated fully, once, before anything is stored: a bad scene leaves no
  // trace. The run decodes the stored bytes again and Simulation::Create validates them.
  SEEP_ASSIGN_OR_RETURN(const core::SceneSpec spec, SceneFromProto(scene));
  SEEP_RETURN_IF_ERROR(CheckJobFitsMemory(spec, guards_.job_memory_limit_bytes));
  std::string bytes;
  if (!scene.SerializeToString(&bytes)) return core::Internal("scene: could not serialize");
  return bytes;
}

grpc::Status SeepServiceImpl::GetJob(grpc::ServerContext* ctx, const v1::GetJobRequest* req,
                                     v1::GetJobResponse* resp) {
  return Guarded(ctx, "GetJob", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const JobRecord job, LoadJob(req->id()));
    JobToProto(job, /*with_scene=*/true, resp->mutable_job());
    SetHeldReason(HeldReason(store_.free_space()), *resp->mutable_job());
    if (job.placement) {
      // The batch job's state as the executor last saw it; unknown when seepd did not submit it.
      if (auto batch = store_.GetBatchJob(job.placement->batch_job_id); batch.ok()) {
        resp->mutable_job()->mutable_batch()->set_state(batch->state);
        if (job.placement->node.empty())
          resp->mutable_job()->mutable_batch()->set_node(batch->node);
      } else if (batch.status().code() != core::StatusCode::kNotFound) {
        return batch.status();
      }
    }
    return core::Status::Ok();
  });
}

grpc::Status SeepServiceImpl::ListJobs(grpc::ServerContext* ctx, const v1::ListJobsRequest* req,
                                       v1::ListJobsResponse* resp) {
  return Guarded(ctx, "ListJobs", [&]() -> core::Status {
    SEEP_ASSIGN_OR_RETURN(const std::optional<std::int64_t> cursor,
                          DecodePageToken(req->page_token(), *req, "ListJobs"));
    JobFilter filter;
    for (const auto& [list, size] :
         {std::pair{"states", req->states_size()}, std::pair{"kinds", req->kinds_size()}}) {
      if (size > kMaxFilterValues) {
        return core::InvalidArgument(
            fmt::format("{}: at most {} values (got {})", list, kMaxFilterValues, size));
      }
    }
    for (const int state : req->states()) {
      const auto known = JobStateFromProto(static_cast<v1::JobState>(state));
      if (!known) return core::InvalidArgument(fmt::format("states: {} is not a job state", state));
      filter.states.push_back(*known);
    }
    if (req->name_contains().size() > kMaxNameFilterLength) {
      return core::InvalidArgument(
          fmt::format("name_contains: at most {} characters", kMaxNameFilterLength));
    }
    filter.name_contains = req->name_contains();
    for (const int kind : req->kinds()) {
      const auto known = JobKindFromProto(static_cast<v1::JobKind>(kind));
      if (!known) return core::InvalidArgument(fmt::format("kinds: {} is not a job kind", kind));
      filter.kinds.push_back(*known);
    }
    SEEP_ASSIGN_OR_RETURN(filter.labels, CheckLabels(req->labels()));
    SEEP_ASSIGN_OR_RETURN(JobPage page, store_.List(PageSize(req->page_size()), cursor, filter));
    const std::string held = HeldReason(store_.free_space());
    for (JobRecord& job : page.jobs) {
      if (job.state == JobState::kRunning) {
        if (auto live = hub_.Live(job.id)) job.progress = *live;
      }
      v1::Job* wire = resp->add_jobs();
      JobToProto(job, /*with_scene=*/false, wire);
      SetHeldReason(held, *wire);
    }
    if (page.next_cursor) resp->set_next_page_token(EncodePageToken(*page.next_cursor, *req));
    return core::Status::Ok();
  });
}

grpc::Status SeepServiceImpl::WatchJob(grpc::ServerContext* ctx, const v1::WatchJobRequest* req,
                                       grpc::ServerWriter<v1::JobEvent>* writer) {
  return Guarded(ctx, "WatchJob", [&]() -> grpc::Status {
    if (core::Status s = RequireId(req->id(), "id"); !s.ok()) return ToGrpcStatus(s);
    // Followed before the first read, so that no change after it goes unseen.
    const std::optional<JobHub::Follower> follower =
        hub_.Follow(req->id(), guards_.max_watch_streams);
    if (!follower) {
      return {grpc::StatusCode::RESOURCE_EXHAUSTED,
              fmt::format("WatchJob: {} streams follow jobs already, the most this seepd serves "
                          "at once (--max-watch-streams); try again later or poll GetJob",
                          guards_.max_watch_streams)};
    }
    return ToGrpcStatus(StreamJob(*ctx, req->id(), *follower, *writer));
  });
}

core::Status SeepServiceImpl::StreamJob(grpc::ServerContext& ctx, const std::string& id,
                                        const JobHub::Follower& follower,
                                        grpc::ServerWriter<v1::JobEvent>& writer) {
  // Only this job's changes wake the stream. Progress alone is laid over the record read last;
  // the store (without the scene) is read again when the record changed, and once a second for
  // what the hub never hears of.
  JobHub::Versions seen = follower.versions();
  SEEP_ASSIGN_OR_RETURN(JobRecord job, store_.GetWithoutScene(id));
  std::string last_sent;
  for (;;) {
    if (job.state == JobState::kRunning) {
      if (auto live = follower.live()) job.progress = std::move(*live);
    }
    v1::JobEvent event;
    JobToProto(job, /*with_scene=*/false, event.mutable_job());
    SetHeldReason(HeldReason(store_.free_space()), *event.mutable_job());
    if (event.job().has_result()) *event.mutable_result() = event.job().result();
    std::string bytes = event.SerializeAsString();
    if (bytes != last_sent) {
      if (!writer.Write(event)) return core::Cancelled("watcher went away");
      last_sent = std::move(bytes);
    }
    if (IsTerminal(job.state)) return core::Status::Ok();
    if (ctx.IsCancelled()) return core::Cancelled("watch cancelled");
    if (hub_.closed()) return core::Unavailable("seepd is shutting down");
    const JobHub::Versions now = follower.WaitForChange(seen, std::chrono::seconds(1));
    if (now.record != seen.record || now == seen) {
      SEEP_ASSIGN_OR_RETURN(job, store_.GetWithoutScene(id));
    }
    seen = now;
  }
}

grpc::Status SeepServiceImpl::CancelJob(grpc::ServerContext* ctx, const v1::CancelJobRequest* req,
                                        v1::CancelJobResponse* resp) {
  return Guarded(ctx, "CancelJob", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const JobRecord job, CancelOne(req->id()));
    SEEP_ASSIGN_OR_RETURN(const JobRecord current, LoadJob(job.id));
    JobToProto(current, /*with_scene=*/false, resp->mutable_job());
    return core::Status::Ok();
  });
}

grpc::Status SeepServiceImpl::ResumeJob(grpc::ServerContext* ctx, const v1::ResumeJobRequest* req,
                                        v1::ResumeJobResponse* resp) {
  return Guarded(ctx, "ResumeJob", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const JobRecord job, ResumeOne(req->id()));
    JobToProto(job, /*with_scene=*/false, resp->mutable_job());
    return core::Status::Ok();
  });
}

core::Result<JobRecord> SeepServiceImpl::CancelOne(const std::string& id) {
  SEEP_ASSIGN_OR_RETURN(JobRecord job, store_.Cancel(id, NowMs()));
  if (job.state == JobState::kRunning) {
    logger_->info("job {}: cancel requested while running", job.id);
    if (hooks_.cancel_running) hooks_.cancel_running(job.id);
  } else {
    logger_->info("job {}: cancelled before it started", job.id);
  }
  hub_.RecordChanged(job.id);
  return job;
}

core::Result<JobRecord> SeepServiceImpl::ResumeOne(const std::string& id) {
  SEEP_ASSIGN_OR_RETURN(JobRecord job, store_.Resume(id));
  logger_->info("job {}: resumed as attempt {} (runs again from the start)", job.id, job.attempt);
  hub_.RecordChanged(job.id);
  if (hooks_.wake_workers) hooks_.wake_workers();
  return job;
}

grpc::Status SeepServiceImpl::GetResult(grpc::ServerContext* ctx, const v1::GetResultRequest* req,
                                        v1::GetResultResponse* resp) {
  return Guarded(ctx, "GetResult", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const JobRecord job, store_.Get(req->id()));
    if (job.state != JobState::kSucceeded) {
      return core::FailedPrecondition(fmt::format("job {} is {}; only a SUCCEEDED job has a result",
                                                  job.id, JobStateName(job.state)));
    }
    v1::Job wire;
    JobToProto(job, /*with_scene=*/false, &wire);
    resp->set_job_id(job.id);
    *resp->mutable_result() = wire.result();
    return core::Status::Ok();
  });
}

}  // namespace seep::service
