// SeepServiceImpl's sweep calls: a seep.v1.Sweep expanded into normal jobs stored in one
// transaction, read back with their states and metrics, and cancelled, resumed or deleted as a
// whole through the per-job logic of CancelJob, ResumeJob and DeleteJob.
#include <fmt/format.h>
#include <google/protobuf/util/time_util.h>

#include <cstring>

#include "codec/field_path.h"
#include "codec/job_codec.h"
#include "codec/sweep_plan.h"
#include "jobs/wall_clock.h"
#include "rpc/handler.h"
#include "rpc/job_labels.h"
#include "rpc/seep_service.h"

namespace seep::service {
namespace {

// A sweep's size: enough for the campaigns users run on one seepd, small enough that its one
// transaction and its GetSweep stay quick.
constexpr std::size_t kMaxSweepJobs = 10'000;
// The scenes of all a sweep's jobs together; each is also held to --max-scene-bytes.
constexpr std::size_t kMaxSweepSceneBytes = std::size_t{1} << 30;
// Every job carries this label with its sweep's id.
constexpr const char* kSweepLabel = "sweep";

const google::protobuf::Message& BaseOf(const v1::Sweep& sweep) {
  if (sweep.has_calibration()) return sweep.calibration();
  return sweep.scene();
}

// The sweep's own name, else its base's (empty when neither has one).
const std::string& SweepName(const v1::Sweep& sweep) {
  if (!sweep.name().empty()) return sweep.name();
  return sweep.has_calibration() ? sweep.calibration().name() : sweep.scene().name();
}

// A point whose scene (or calibration) fails its checks. When the failing field is a swept one,
// the error names that axis' value (where the CLI finds its line); otherwise the base and the
// point's settings.
core::Status PointError(const SweepPlan& plan, const SweepPoint& point, std::size_t position,
                        std::string_view root, const core::Status& status) {
  const std::string& message = status.message();
  for (std::size_t i = 0; i < plan.parameters.size(); ++i) {
    const std::string field = fmt::format("{}.{}", root, plan.parameters[i]);
    const bool names_it =
        message.rfind(field, 0) == 0 &&
        (message.size() == field.size() || std::strchr(":.[ ", message[field.size()]) != nullptr);
    if (names_it) {
      return core::Status(
          status.code(),
          fmt::format("sweep.{}: {} = {} makes an invalid {}: {}", point.value_fields[i],
                      plan.parameters[i], SettingValueText(point.settings[i]), root, message));
    }
  }
  return core::Status(status.code(),
                      fmt::format("sweep.{}: job {} of the sweep ({}) is an invalid {}: {}", root,
                                  position, DescribeSweepPoint(plan, point), root, message));
}

void CountState(JobState state, v1::SweepCounts* counts) {
  switch (state) {
    case JobState::kQueued:
      counts->set_queued(counts->queued() + 1);
      break;
    case JobState::kRunning:
      counts->set_running(counts->running() + 1);
      break;
    case JobState::kSucceeded:
      counts->set_succeeded(counts->succeeded() + 1);
      break;
    case JobState::kFailed:
      counts->set_failed(counts->failed() + 1);
      break;
    case JobState::kCancelled:
      counts->set_cancelled(counts->cancelled() + 1);
      break;
  }
}

core::Result<v1::Sweep> ParseDefinition(const SweepRecord& record) {
  v1::Sweep definition;
  if (!definition.ParseFromString(record.definition)) {
    return core::DataLoss(fmt::format("sweep {}: its stored definition does not parse", record.id));
  }
  return definition;
}

}  // namespace

core::Result<std::vector<JobRecord>> SeepServiceImpl::SweepJobs(
    const v1::SubmitSweepRequest& request, const std::string& sweep_id) {
  const v1::Sweep& sweep = request.sweep();
  const bool calibration = sweep.has_calibration();
  const std::string_view root = calibration ? "calibration" : "scene";
  const google::protobuf::Message& base = BaseOf(sweep);
  if (const std::size_t bytes = base.ByteSizeLong(); bytes > guards_.max_scene_bytes) {
    return core::InvalidArgument(
        fmt::format("sweep.{}: {} bytes exceed the limit of {} (seepd --max-scene-bytes)", root,
                    bytes, guards_.max_scene_bytes));
  }
  using Labels = std::vector<std::pair<std::string, std::string>>;
  SEEP_ASSIGN_OR_RETURN(Labels labels, CheckLabels(request.labels()));
  for (const auto& [key, value] : labels) {
    if (key == kSweepLabel) {
      return core::InvalidArgument(fmt::format(
          "labels[\"{}\"]: is set by the sweep itself ({}=<the sweep's id>)", key, key));
    }
  }
  labels.emplace_back(kSweepLabel, sweep_id);
  SEEP_ASSIGN_OR_RETURN(const SweepPlan plan, PlanSweep(sweep, base, kMaxSweepJobs));
  const std::string& name = SweepName(sweep);
  std::vector<JobRecord> jobs;
  std::size_t total_bytes = 0;
  const std::int64_t now_ms = NowMs();
  for (std::size_t position = 0; position < plan.points.size(); ++position) {
    const SweepPoint& point = plan.points[position];
    std::unique_ptr<google::protobuf::Message> message(base.New());
    message->CopyFrom(base);
    SEEP_RETURN_IF_ERROR(ApplySweepPoint(plan, point, *message));
    JobRecord job;
    if (calibration) {
      const auto prepared = PrepareCalibrationJob(static_cast<const v1::Calibration&>(*message));
      if (!prepared.ok()) return PointError(plan, point, position, root, prepared.status());
      job.kind = JobKind::kCalibration;
      job.scene = prepared->bytes;
    } else {
      auto prepared = PrepareSimulationJob(static_cast<const v1::Scene&>(*message));
      if (!prepared.ok()) return PointError(plan, point, position, root, prepared.status());
      job.scene = std::move(*prepared);
    }
    total_bytes += job.scene.size();
    if (total_bytes > kMaxSweepSceneBytes) {
      return core::InvalidArgument(
          fmt::format("sweep: its jobs' {}s take more than the {} bytes a sweep may store", root,
                      kMaxSweepSceneBytes));
    }
    SEEP_ASSIGN_OR_RETURN(job.id, NewRandomId('j'));
    job.name = fmt::format("{}/{}", name.empty() ? sweep_id : name, position);
    job.labels = labels;
    job.priority = request.priority();
    job.build_id = build_id_;
    job.created_at_ms = now_ms;
    jobs.push_back(std::move(job));
  }
  return jobs;
}

core::Status SeepServiceImpl::FillSweepStatus(const SweepRecord& record, v1::SweepStatus* out,
                                              v1::Sweep* definition_out) {
  // The settings of every position come from the definition again: the store keeps the sweep
  // once, not a copy of its values per job.
  SEEP_ASSIGN_OR_RETURN(const v1::Sweep definition, ParseDefinition(record));
  if (definition_out != nullptr) *definition_out = definition;
  SEEP_ASSIGN_OR_RETURN(const SweepPlan plan,
                        PlanSweep(definition, BaseOf(definition), kMaxSweepJobs));
  out->set_id(record.id);
  out->set_name(record.name);
  if (record.request_id) out->set_request_id(*record.request_id);
  *out->mutable_created_at() =
      google::protobuf::util::TimeUtil::MillisecondsToTimestamp(record.created_at_ms);
  for (const std::string& path : plan.parameters) out->add_parameters(path);
  double done = 0.0;
  for (const auto& [position, job_id] : record.jobs) {
    const core::Result<JobRecord> job = LoadJob(job_id, /*with_scene=*/false);
    if (job.status().code() == core::StatusCode::kNotFound) continue;  // deleted meanwhile
    SEEP_RETURN_IF_ERROR(job.status());
    v1::SweepJob* member = out->add_jobs();
    member->set_position(position);
    if (position < plan.points.size()) {
      for (const v1::SweepSetting& setting : plan.points[position].settings) {
        *member->add_settings() = setting;
      }
    }
    JobToProto(*job, /*with_scene=*/false, member->mutable_job());
    member->mutable_job()->mutable_result()->clear_series();
    if (!member->job().has_result() || member->job().result().ByteSizeLong() == 0) {
      member->mutable_job()->clear_result();
    }
    CountState(job->state, out->mutable_counts());
    done += IsTerminal(job->state) ? 1.0 : job->progress.fraction_done;
  }
  out->set_fraction_done(out->jobs_size() == 0 ? 1.0 : done / out->jobs_size());
  return core::Status::Ok();
}

grpc::Status SeepServiceImpl::SubmitSweep(grpc::ServerContext* ctx,
                                          const v1::SubmitSweepRequest* req,
                                          v1::SubmitSweepResponse* resp) {
  return Guarded(ctx, "SubmitSweep", [&]() -> core::Status {
    if (!req->has_sweep()) return core::InvalidArgument("sweep: is required");
    const v1::Sweep& sweep = req->sweep();
    if (sweep.has_scene() == sweep.has_calibration()) {
      return core::InvalidArgument(
          sweep.has_scene() ? "sweep.calibration: set either scene or calibration, not both"
                            : "sweep.scene: is required (or sweep.calibration)");
    }
    SEEP_RETURN_IF_ERROR(CheckNameLength(sweep.name(), "sweep.name"));
    SEEP_RETURN_IF_ERROR(CheckRequestId(req->request_id()));
    SEEP_RETURN_IF_ERROR(CheckPriority(req->priority()));
    SweepRecord record;
    SEEP_ASSIGN_OR_RETURN(record.id, NewRandomId('s'));
    // Every point is made and validated before anything is stored: a bad one leaves no trace.
    SEEP_ASSIGN_OR_RETURN(const std::vector<JobRecord> jobs, SweepJobs(*req, record.id));
    if (!req->request_id().empty()) record.request_id = req->request_id();
    record.name = SweepName(sweep);
    if (!sweep.SerializeToString(&record.definition)) {
      return core::Internal("sweep: could not serialize");
    }
    record.created_at_ms = NowMs();
    SEEP_ASSIGN_OR_RETURN(const SweepInsertOutcome outcome, store_.InsertSweep(record, jobs));
    if (outcome.created) {
      logger_->info("sweep {} submitted ('{}') with {} job(s)", outcome.sweep.id,
                    outcome.sweep.name, outcome.sweep.jobs.size());
      if (hooks_.wake_workers) hooks_.wake_workers();
    }
    SEEP_RETURN_IF_ERROR(FillSweepStatus(outcome.sweep, resp->mutable_sweep()));
    resp->set_created(outcome.created);
    return core::Status::Ok();
  });
}

grpc::Status SeepServiceImpl::GetSweep(grpc::ServerContext* ctx, const v1::GetSweepRequest* req,
                                       v1::GetSweepResponse* resp) {
  return Guarded(ctx, "GetSweep", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const SweepRecord record, store_.GetSweep(req->id()));
    return FillSweepStatus(record, resp->mutable_sweep(), resp->mutable_definition());
  });
}

grpc::Status SeepServiceImpl::CancelSweep(grpc::ServerContext* ctx,
                                          const v1::CancelSweepRequest* req,
                                          v1::CancelSweepResponse* resp) {
  return Guarded(ctx, "CancelSweep", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const SweepRecord record, store_.GetSweep(req->id()));
    // Queued jobs first, so that a worker freed by a cancelled running job finds none of them.
    for (const JobState pass : {JobState::kQueued, JobState::kRunning}) {
      for (const auto& [position, job_id] : record.jobs) {
        const core::Result<JobRecord> job = store_.GetWithoutScene(job_id);
        if (!job.ok() || job->state != pass) continue;
        const core::Result<JobRecord> cancelled = CancelOne(job_id);
        // A job that finished (or was deleted) since it was read has nothing left to cancel.
        if (cancelled.status().code() == core::StatusCode::kFailedPrecondition ||
            cancelled.status().code() == core::StatusCode::kNotFound) {
          continue;
        }
        SEEP_RETURN_IF_ERROR(cancelled.status());
        if (cancelled->state == JobState::kCancelled) {
          resp->set_jobs_cancelled(resp->jobs_cancelled() + 1);
        } else {
          resp->set_cancels_requested(resp->cancels_requested() + 1);
        }
      }
    }
    if (resp->jobs_cancelled() + resp->cancels_requested() == 0) {
      return core::FailedPrecondition(fmt::format(
          "sweep {} has no QUEUED or RUNNING job; only those can be cancelled", record.id));
    }
    logger_->info("sweep {}: {} job(s) cancelled, {} running job(s) asked to stop", record.id,
                  resp->jobs_cancelled(), resp->cancels_requested());
    return FillSweepStatus(record, resp->mutable_sweep());
  });
}

grpc::Status SeepServiceImpl::ResumeSweep(grpc::ServerContext* ctx,
                                          const v1::ResumeSweepRequest* req,
                                          v1::ResumeSweepResponse* resp) {
  return Guarded(ctx, "ResumeSweep", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    SEEP_ASSIGN_OR_RETURN(const SweepRecord record, store_.GetSweep(req->id()));
    for (const auto& [position, job_id] : record.jobs) {
      const core::Result<JobRecord> job = store_.GetWithoutScene(job_id);
      if (!job.ok() || (job->state != JobState::kFailed && job->state != JobState::kCancelled)) {
        continue;
      }
      const core::Result<JobRecord> resumed = ResumeOne(job_id);
      if (resumed.status().code() == core::StatusCode::kFailedPrecondition ||
          resumed.status().code() == core::StatusCode::kNotFound) {
        continue;  // resumed (or deleted) by another call since it was read
      }
      SEEP_RETURN_IF_ERROR(resumed.status());
      resp->set_jobs_resumed(resp->jobs_resumed() + 1);
    }
    if (resp->jobs_resumed() == 0) {
      return core::FailedPrecondition(fmt::format(
          "sweep {} has no FAILED or CANCELLED job; only those can be resumed", record.id));
    }
    logger_->info("sweep {}: {} job(s) resumed", record.id, resp->jobs_resumed());
    return FillSweepStatus(record, resp->mutable_sweep());
  });
}

grpc::Status SeepServiceImpl::DeleteSweep(grpc::ServerContext* ctx,
                                          const v1::DeleteSweepRequest* req,
                                          v1::DeleteSweepResponse* resp) {
  return Guarded(ctx, "DeleteSweep", [&]() -> core::Status {
    SEEP_RETURN_IF_ERROR(RequireId(req->id(), "id"));
    // The records go first, in one transaction; the files after (as DeleteJob).
    const core::Result<SweepDeletion> deletion = store_.DeleteSweep(req->id());
    if (!deletion.ok()) {
      if (deletion.status().code() == core::StatusCode::kNotFound) return deletion.status();
      return core::Status(deletion.status().code(),
                          fmt::format("sweep {}: {}", req->id(), deletion.status().message()));
    }
    const RemovedFiles removed = FinishDeletion(deletion->job_ids, deletion->checkpoints);
    logger_->info("sweep {} deleted with its {} job(s) and {} checkpoint file(s), {} bytes",
                  req->id(), deletion->job_ids.size(), removed.files, removed.bytes);
    resp->set_id(req->id());
    resp->set_jobs_deleted(static_cast<std::uint32_t>(deletion->job_ids.size()));
    resp->set_checkpoints_deleted(static_cast<std::uint32_t>(removed.files));
    resp->set_bytes_freed(removed.bytes);
    return core::Status::Ok();
  });
}

}  // namespace seep::service
