#include "rpc/held_reason.h"

#include <fmt/format.h>

namespace seep::service {

std::string HeldReason(const FreeSpaceGuard& free_space) {
  const FreeSpaceReading reading = free_space.Measure();
  if (!reading.low()) return {};
  return fmt::format(
      "disk full: {}: no job starts, and a running one fails at its next checkpoint, until space "
      "is freed",
      reading.Describe());
}

void SetHeldReason(const std::string& reason, v1::Job& job) {
  if (reason.empty()) return;
  if (job.state() == v1::JOB_STATE_QUEUED || job.state() == v1::JOB_STATE_RUNNING) {
    job.set_held_reason(reason);
  }
}

}  // namespace seep::service
