// The WorkerService's messages (proto/seep/v1/worker_service.proto) <-> the store's forms: a
// claimed job as a remote worker receives it.
#pragma once

#include "seep/v1/worker_service.pb.h"
#include "store/job_record.h"

namespace seep::service {

// What a worker needs of a claimed job (id, name, scene, attempt, lease, fork origin, progress).
void LeasedJobToProto(const JobRecord& job, v1::LeasedJob* out);
// The JobRecord a remote worker runs: RUNNING, a simulation, under the lease it was given.
JobRecord LeasedJobFromProto(const v1::LeasedJob& leased);

}  // namespace seep::service
