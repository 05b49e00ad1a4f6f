// What the store keeps of a sweep: plain data, its definition as the serialized seep.v1.Sweep
// bytes (the store needs no protobuf), and which job is which of its points.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "job_record.h"

namespace seep::service {

struct SweepRecord {
  std::string id;
  std::optional<std::string> request_id;
  std::string name;
  std::string definition;  // serialized seep.v1.Sweep, as submitted
  std::int64_t created_at_ms = 0;
  // (position, job id), by position; a job deleted on its own is missing.
  std::vector<std::pair<std::uint32_t, std::string>> jobs;
};

struct SweepInsertOutcome {
  SweepRecord sweep;
  bool created = false;  // false: request_id matched an existing sweep, which is returned
};

// What DeleteSweep removed: the jobs, and their checkpoint records for the caller to remove.
struct SweepDeletion {
  std::vector<std::string> job_ids;
  std::vector<CheckpointRecord> checkpoints;
};

}  // namespace seep::service
