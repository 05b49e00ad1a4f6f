#include "job_codec.h"

#include <google/protobuf/util/time_util.h>

#include <algorithm>

namespace seep::service {
namespace {

void SetTime(std::int64_t ms, google::protobuf::Timestamp* out) {
  *out = google::protobuf::util::TimeUtil::MillisecondsToTimestamp(ms);
}

}  // namespace

v1::JobState JobStateToProto(JobState state) {
  switch (state) {
    case JobState::kQueued:
      return v1::JOB_STATE_QUEUED;
    case JobState::kRunning:
      return v1::JOB_STATE_RUNNING;
    case JobState::kSucceeded:
      return v1::JOB_STATE_SUCCEEDED;
    case JobState::kFailed:
      return v1::JOB_STATE_FAILED;
    case JobState::kCancelled:
      return v1::JOB_STATE_CANCELLED;
  }
  return v1::JOB_STATE_UNSPECIFIED;
}

std::optional<JobState> JobStateFromProto(v1::JobState state) {
  switch (state) {
    case v1::JOB_STATE_QUEUED:
      return JobState::kQueued;
    case v1::JOB_STATE_RUNNING:
      return JobState::kRunning;
    case v1::JOB_STATE_SUCCEEDED:
      return JobState::kSucceeded;
    case v1::JOB_STATE_FAILED:
      return JobState::kFailed;
    case v1::JOB_STATE_CANCELLED:
      return JobState::kCancelled;
    default:
      return std::nullopt;
  }
}

v1::JobKind JobKindToProto(JobKind kind) {
  return kind == JobKind::kCalibration ? v1::JOB_KIND_CALIBRATION : v1::JOB_KIND_SIMULATION;
}

std::optional<JobKind> JobKindFromProto(v1::JobKind kind) {
  switch (kind) {
    case v1::JOB_KIND_SIMULATION:
      return JobKind::kSimulation;
    case v1::JOB_KIND_CALIBRATION:
      return JobKind::kCalibration;
    default:
      return std::nullopt;
  }
}

void JobToProto(const JobRecord& job, bool with_scene, v1::Job* out) {
  out->set_id(job.id);
  out->set_name(job.name);
  out->set_request_id(job.request_id.value_or(""));
  out->set_state(JobStateToProto(job.state));
  out->set_kind(JobKindToProto(job.kind));
  if (with_scene && job.kind == JobKind::kCalibration) {
    (void)out->mutable_calibration()->ParseFromString(job.scene);
  } else if (with_scene) {
    (void)out->mutable_scene()->ParseFromString(job.scene);
  }
  SetTime(job.created_at_ms, out->mutable_created_at());
  if (job.started_at_ms) SetTime(*job.started_at_ms, out->mutable_started_at());
  if (job.finished_at_ms) SetTime(*job.finished_at_ms, out->mutable_finished_at());
  ProgressToProto(job.progress, out->mutable_progress());
  if (!job.error_code.empty()) {
    out->mutable_error()->set_code(job.error_code);
    out->mutable_error()->set_message(job.error_message);
  }
  if (job.state == JobState::kSucceeded) {
    auto* result = out->mutable_result();
    for (const auto& [name, value] : job.metrics) (*result->mutable_metrics())[name] = value;
    result->set_wall_time_s(job.wall_time_s);
    result->set_state_sha256(job.state_sha256);
    auto* series = result->mutable_series();
    for (const auto& c : job.series_columns) series->add_columns(c);
    series->mutable_values()->Assign(job.series_values.begin(), job.series_values.end());
  }
  out->set_build_id(job.build_id);
  out->set_attempt(job.attempt);
  out->set_priority(job.priority);
  out->set_cancel_requested(job.cancel_requested);
  for (const auto& [key, value] : job.labels) (*out->mutable_labels())[key] = value;
  if (job.parent_job_id) {
    out->set_parent_job_id(*job.parent_job_id);
    out->set_parent_step(job.parent_step);
  }
  for (const std::string& child : job.child_job_ids) out->add_child_job_ids(child);
  if (job.placement) {
    out->mutable_batch()->set_system("slurm");
    out->mutable_batch()->set_job_id(job.placement->batch_job_id);
    out->mutable_batch()->set_node(job.placement->node);
  }
}

void JobEventToProto(const JobEventRecord& event, v1::JobHistoryEvent* out) {
  SetTime(event.at_ms, out->mutable_at());
  out->set_kind(event.kind);
  out->set_message(event.message);
}

void ProgressToProto(const JobProgress& progress, v1::Progress* out) {
  out->set_step(progress.step);
  out->set_time_s(progress.time_s);
  out->set_fraction_done(progress.fraction_done);
  out->set_eta_s(progress.eta_s);
  out->set_stage_index(progress.stage_index);
  out->set_stage_count(progress.stage_count);
  out->set_stage_name(progress.stage_name);
  for (const auto& [name, value] : progress.latest) (*out->mutable_latest())[name] = value;
}

JobProgress ProgressFromProto(const v1::Progress& progress) {
  JobProgress out = JobProgress::At(progress.step(), progress.time_s(), progress.fraction_done(),
                                    progress.eta_s());
  out.stage_index = progress.stage_index();
  out.stage_count = progress.stage_count();
  out.stage_name = progress.stage_name();
  // A proto map has no order: by name, as the store and the printers show them anyway.
  out.latest.assign(progress.latest().begin(), progress.latest().end());
  std::sort(out.latest.begin(), out.latest.end());
  return out;
}

}  // namespace seep::service
