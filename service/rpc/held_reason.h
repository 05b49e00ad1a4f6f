// Why a QUEUED or RUNNING job does not go on now (seep.v1.Job.held_reason), said with the job in
// every answer that carries it: measured when answering, never stored, so that it holds even
// when the disk is too full for a single write.
#pragma once

#include <string>

#include "seep/v1/job_service.pb.h"
#include "store/free_space.h"

namespace seep::service {

// Empty while the data folder's file system is above --min-free-disk-mb; else the figures and
// what it means for the jobs.
std::string HeldReason(const FreeSpaceGuard& free_space);
// Sets `reason` on `job` when it is QUEUED or RUNNING (a finished job is held by nothing).
void SetHeldReason(const std::string& reason, v1::Job& job);

}  // namespace seep::service
