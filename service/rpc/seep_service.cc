#include "rpc/seep_service.h"

#include <fmt/format.h>

#include <chrono>
#include <exception>
#include <random>

#include "codec/job_codec.h"
#include "codec/scene_codec.h"
#include "jobs/wall_clock.h"
#include "rpc/status_mapping.h"

namespace seep::service {
namespace {

constexpr std::uint32_t kDefaultPageSize = 50;
constexpr std::uint32_t kMaxPageSize = 1000;
constexpr std::size_t kMaxRequestIdLength = 200;
constexpr std::size_t kMaxNameFilterLength = 200;

// Job ids are random, not sequential, so that two servers' ids never collide when records are
// merged; 64 bits of entropy.
std::string NewJobId() {
  thread_local std::mt19937_64 rng{std::random_device{}()};
  return fmt::format("j-{:016x}", rng());
}

// Every handler body runs inside this: the caller is authenticated first (when seepd has a
// token), and no exception escapes into gRPC.
template <typename Fn>
grpc::Status Guarded(const std::shared_ptr<spdlog::logger>& logger, const ServiceGuards& guards,
                     const grpc::ServerContext* ctx, const char* rpc, Fn&& fn) {
  if (guards.auth != nullptr) {
    if (grpc::Status denied = guards.auth->Check(*ctx); !denied.ok()) {
      logger->warn("{} from {}: refused: {}", rpc, ctx->peer(), denied.error_message());
      return denied;
    }
  }
  try {
    return fn();
  } catch (const std::exception& e) {
    logger->error("{}: unexpected exception: {}", rpc, e.what());
    return {grpc::StatusCode::INTERNAL, fmt::format("{}: internal error", rpc)};
  }
}

}  // namespace

SeepServiceImpl::SeepServiceImpl(JobStore& store, JobHub& hub, std::string build_id,
                                 ServiceHooks hooks, std::shared_ptr<spdlog::logger> logger,
                                 ServiceGuards guards)
    : store_(store),
      hub_(hub),
      build_id_(std::move(build_id)),
      hooks_(std::move(hooks)),
      logger_(std::move(logger)),
      guards_(guards) {}

core::Result<JobRecord> SeepServiceImpl::LoadJob(const std::string& id) {
  SEEP_ASSIGN_OR_RETURN(JobRecord job, store_.Get(id));
  if (job.state == JobState::kRunning) {
    if (auto live = hub_.Live(id)) job.progress = *live;
  }
  return job;
}

grpc::Status SeepServiceImpl::SubmitJob(grpc::ServerContext* ctx, const v1::SubmitJobRequest* req,
                                        v1::SubmitJobResponse* resp) {
  return Guarded(logger_, guards_, ctx, "SubmitJob", [&]() -> grpc::Status {
    if (req->has_scene() && req->has_calibration()) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              "calibration: set either scene (a simulation) or calibration, not both"};
    }
    if (!req->has_scene() && !req->has_calibration()) {
      return {grpc::StatusCode::INVALID_ARGUMENT, "scene: is required"};
    }
    if (req->request_id().size() > kMaxRequestIdLength) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              fmt::format("request_id: at most {} characters", kMaxRequestIdLength)};
    }
    JobRecord job;
    job.id = NewJobId();
    if (req->has_calibration()) {
      // seep_service_calibrations.cc: checks, from_job_id, validation, serialization.
      auto prepared = PrepareCalibrationJob(req->calibration());
      if (!prepared.ok()) return ToGrpcStatus(prepared.status());
      job.kind = JobKind::kCalibration;
      job.name = prepared->name;
      job.scene = std::move(prepared->bytes);
      if (job.name.empty()) job.name = job.id;
    } else {
      // Measured before decoding, so an oversized scene costs no decode and leaves no trace.
      if (const std::size_t bytes = req->scene().ByteSizeLong(); bytes > guards_.max_scene_bytes) {
        return {grpc::StatusCode::INVALID_ARGUMENT,
                fmt::format("scene: {} bytes exceed the limit of {} (seepd --max-scene-bytes)",
                            bytes, guards_.max_scene_bytes)};
      }
      // Validate fully before anything is stored: a bad scene leaves no trace.
      if (auto spec = SceneFromProto(req->scene()); !spec.ok()) {
        return ToGrpcStatus(spec.status());
      }
      job.name = req->scene().name().empty() ? job.id : req->scene().name();
      if (!req->scene().SerializeToString(&job.scene)) {
        return {grpc::StatusCode::INTERNAL, "scene: could not serialize"};
      }
    }
    if (!req->request_id().empty()) job.request_id = req->request_id();
    job.build_id = build_id_;
    job.created_at_ms = NowMs();
    auto outcome = store_.Insert(job);
    if (!outcome.ok()) return ToGrpcStatus(outcome.status());
    if (outcome->created) {
      logger_->info("{} job {} submitted ('{}')",
                    outcome->job.kind == JobKind::kCalibration ? "calibration" : "simulation",
                    outcome->job.id, outcome->job.name);
      hub_.NotifyChanged();
      if (hooks_.wake_workers) hooks_.wake_workers();
    }
    auto current = LoadJob(outcome->job.id);
    if (!current.ok()) return ToGrpcStatus(current.status());
    JobToProto(*current, /*with_scene=*/true, resp->mutable_job());
    resp->set_created(outcome->created);
    return grpc::Status::OK;
  });
}

grpc::Status SeepServiceImpl::GetJob(grpc::ServerContext* ctx, const v1::GetJobRequest* req,
                                     v1::GetJobResponse* resp) {
  return Guarded(logger_, guards_, ctx, "GetJob", [&]() -> grpc::Status {
    if (req->id().empty()) return {grpc::StatusCode::INVALID_ARGUMENT, "id: is required"};
    auto job = LoadJob(req->id());
    if (!job.ok()) return ToGrpcStatus(job.status());
    JobToProto(*job, /*with_scene=*/true, resp->mutable_job());
    return grpc::Status::OK;
  });
}

grpc::Status SeepServiceImpl::ListJobs(grpc::ServerContext* ctx, const v1::ListJobsRequest* req,
                                       v1::ListJobsResponse* resp) {
  return Guarded(logger_, guards_, ctx, "ListJobs", [&]() -> grpc::Status {
    const std::uint32_t limit =
        req->page_size() == 0 ? kDefaultPageSize : std::min(req->page_size(), kMaxPageSize);
    std::optional<std::int64_t> cursor;
    if (!req->page_token().empty()) {
      try {
        std::size_t used = 0;
        cursor = std::stoll(req->page_token(), &used);
        if (used != req->page_token().size() || *cursor <= 0) throw std::invalid_argument("");
      } catch (const std::exception&) {
        return {grpc::StatusCode::INVALID_ARGUMENT, "page_token: not a token returned by ListJobs"};
      }
    }
    JobFilter filter;
    for (const int state : req->states()) {
      const auto known = JobStateFromProto(static_cast<v1::JobState>(state));
      if (!known) {
        return {grpc::StatusCode::INVALID_ARGUMENT,
                fmt::format("states: {} is not a job state", state)};
      }
      filter.states.push_back(*known);
    }
    if (req->name_contains().size() > kMaxNameFilterLength) {
      return {grpc::StatusCode::INVALID_ARGUMENT,
              fmt::format("name_contains: at most {} characters", kMaxNameFilterLength)};
    }
    filter.name_contains = req->name_contains();
    for (const int kind : req->kinds()) {
      const auto known = JobKindFromProto(static_cast<v1::JobKind>(kind));
      if (!known) {
        return {grpc::StatusCode::INVALID_ARGUMENT,
                fmt::format("kinds: {} is not a job kind", kind)};
      }
      filter.kinds.push_back(*known);
    }
    auto page = store_.List(limit, cursor, filter);
    if (!page.ok()) return ToGrpcStatus(page.status());
    for (JobRecord& job : page->jobs) {
      if (job.state == JobState::kRunning) {
        if (auto live = hub_.Live(job.id)) job.progress = *live;
      }
      JobToProto(job, /*with_scene=*/false, resp->add_jobs());
    }
    if (page->next_cursor) resp->set_next_page_token(std::to_string(*page->next_cursor));
    return grpc::Status::OK;
  });
}

grpc::Status SeepServiceImpl::WatchJob(grpc::ServerContext* ctx, const v1::WatchJobRequest* req,
                                       grpc::ServerWriter<v1::JobEvent>* writer) {
  return Guarded(logger_, guards_, ctx, "WatchJob", [&]() -> grpc::Status {
    if (req->id().empty()) return {grpc::StatusCode::INVALID_ARGUMENT, "id: is required"};
    std::string last_sent;
    for (;;) {
      const std::uint64_t version = hub_.version();
      auto job = LoadJob(req->id());
      if (!job.ok()) return ToGrpcStatus(job.status());
      v1::JobEvent event;
      JobToProto(*job, /*with_scene=*/false, event.mutable_job());
      if (event.job().has_result()) *event.mutable_result() = event.job().result();
      std::string bytes = event.SerializeAsString();
      if (bytes != last_sent) {
        if (!writer->Write(event)) return {grpc::StatusCode::CANCELLED, "watcher went away"};
        last_sent = std::move(bytes);
      }
      if (IsTerminal(job->state)) return grpc::Status::OK;
      if (ctx->IsCancelled()) return {grpc::StatusCode::CANCELLED, "watch cancelled"};
      if (hub_.closed()) return {grpc::StatusCode::UNAVAILABLE, "seepd is shutting down"};
      hub_.WaitForChange(version, std::chrono::seconds(1));
    }
  });
}

grpc::Status SeepServiceImpl::CancelJob(grpc::ServerContext* ctx, const v1::CancelJobRequest* req,
                                        v1::CancelJobResponse* resp) {
  return Guarded(logger_, guards_, ctx, "CancelJob", [&]() -> grpc::Status {
    if (req->id().empty()) return {grpc::StatusCode::INVALID_ARGUMENT, "id: is required"};
    auto job = store_.Cancel(req->id(), NowMs());
    if (!job.ok()) return ToGrpcStatus(job.status());
    if (job->state == JobState::kRunning) {
      logger_->info("job {}: cancel requested while running", job->id);
      if (hooks_.cancel_running) hooks_.cancel_running(job->id);
    } else {
      logger_->info("job {}: cancelled before it started", job->id);
    }
    hub_.NotifyChanged();
    auto current = LoadJob(job->id);
    if (!current.ok()) return ToGrpcStatus(current.status());
    JobToProto(*current, /*with_scene=*/false, resp->mutable_job());
    return grpc::Status::OK;
  });
}

grpc::Status SeepServiceImpl::ResumeJob(grpc::ServerContext* ctx, const v1::ResumeJobRequest* req,
                                        v1::ResumeJobResponse* resp) {
  return Guarded(logger_, guards_, ctx, "ResumeJob", [&]() -> grpc::Status {
    if (req->id().empty()) return {grpc::StatusCode::INVALID_ARGUMENT, "id: is required"};
    auto job = store_.Resume(req->id());
    if (!job.ok()) return ToGrpcStatus(job.status());
    logger_->info("job {}: resumed as attempt {} (runs again from the start)", job->id,
                  job->attempt);
    hub_.NotifyChanged();
    if (hooks_.wake_workers) hooks_.wake_workers();
    JobToProto(*job, /*with_scene=*/false, resp->mutable_job());
    return grpc::Status::OK;
  });
}

grpc::Status SeepServiceImpl::GetResult(grpc::ServerContext* ctx, const v1::GetResultRequest* req,
                                        v1::GetResultResponse* resp) {
  return Guarded(logger_, guards_, ctx, "GetResult", [&]() -> grpc::Status {
    if (req->id().empty()) return {grpc::StatusCode::INVALID_ARGUMENT, "id: is required"};
    auto job = store_.Get(req->id());
    if (!job.ok()) return ToGrpcStatus(job.status());
    if (job->state != JobState::kSucceeded) {
      return {grpc::StatusCode::FAILED_PRECONDITION,
              fmt::format("job {} is {}; only a SUCCEEDED job has a result", job->id,
                          JobStateName(job->state))};
    }
    v1::Job wire;
    JobToProto(*job, /*with_scene=*/false, &wire);
    resp->set_job_id(job->id);
    *resp->mutable_result() = wire.result();
    return grpc::Status::OK;
  });
}

grpc::Status SeepServiceImpl::ListCalibrations(grpc::ServerContext* ctx,
                                               const v1::ListCalibrationsRequest* req,
                                               v1::ListCalibrationsResponse* resp) {
  return Guarded(logger_, guards_, ctx, "ListCalibrations",
                 [&]() -> grpc::Status { return DoListCalibrations(*req, resp); });
}

grpc::Status SeepServiceImpl::LookupCalibration(grpc::ServerContext* ctx,
                                                const v1::LookupCalibrationRequest* req,
                                                v1::LookupCalibrationResponse* resp) {
  return Guarded(logger_, guards_, ctx, "LookupCalibration",
                 [&]() -> grpc::Status { return DoLookupCalibration(*req, resp); });
}

}  // namespace seep::service
