// JobRecord (the store's form) -> seep.v1.Job (the wire form), and a job's events.
#pragma once

#include <optional>

#include "seep/v1/job_service.pb.h"
#include "store/job_record.h"

namespace seep::service {

v1::JobState JobStateToProto(JobState state);
// nullopt for JOB_STATE_UNSPECIFIED and values outside the enum.
std::optional<JobState> JobStateFromProto(v1::JobState state);
v1::JobKind JobKindToProto(JobKind kind);
// nullopt for JOB_KIND_UNSPECIFIED and values outside the enum.
std::optional<JobKind> JobKindFromProto(v1::JobKind kind);
// with_scene = false leaves Job.scene (or Job.calibration) empty (ListJobs keeps pages small).
void JobToProto(const JobRecord& job, bool with_scene, v1::Job* out);
// A job's progress both ways (the latest samples come back sorted by name).
void ProgressToProto(const JobProgress& progress, v1::Progress* out);
JobProgress ProgressFromProto(const v1::Progress& progress);
void JobEventToProto(const JobEventRecord& event, v1::JobHistoryEvent* out);

}  // namespace seep::service
