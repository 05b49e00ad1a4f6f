#include "codec/worker_codec.h"

#include "codec/job_codec.h"

namespace seep::service {

void LeasedJobToProto(const JobRecord& job, v1::LeasedJob* out) {
  out->set_id(job.id);
  out->set_name(job.name);
  out->set_scene(job.scene);
  out->set_attempt(job.attempt);
  out->set_lease_epoch(job.lease_epoch);
  if (job.parent_job_id) out->set_parent_job_id(*job.parent_job_id);
  out->set_parent_step(job.parent_step);
  ProgressToProto(job.progress, out->mutable_progress());
}

JobRecord LeasedJobFromProto(const v1::LeasedJob& leased) {
  JobRecord job;
  job.id = leased.id();
  job.name = leased.name();
  job.state = JobState::kRunning;
  job.kind = JobKind::kSimulation;
  job.scene = leased.scene();
  job.attempt = leased.attempt();
  job.lease_epoch = leased.lease_epoch();
  if (!leased.parent_job_id().empty()) job.parent_job_id = leased.parent_job_id();
  job.parent_step = leased.parent_step();
  job.progress = ProgressFromProto(leased.progress());
  return job;
}

}  // namespace seep::service
