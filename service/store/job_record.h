// What the store keeps of a job. Plain data: the scene travels as the serialized seep.v1.Scene
// bytes, so the store needs neither protobuf nor the physics.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace seep::service {

enum class JobState { kQueued, kRunning, kSucceeded, kFailed, kCancelled };

const char* JobStateName(JobState state);  // "QUEUED", …; the spelling stored in SQLite
std::optional<JobState> ParseJobState(std::string_view name);
inline bool IsTerminal(JobState s) {
  return s == JobState::kSucceeded || s == JobState::kFailed || s == JobState::kCancelled;
}

struct JobProgress {
  std::uint64_t step = 0;
  double time_s = 0.0;
  double fraction_done = 0.0;
  double eta_s = 0.0;
};

struct JobRecord {
  std::string id;
  std::string name;
  std::optional<std::string> request_id;
  JobState state = JobState::kQueued;
  std::string scene;  // serialized seep.v1.Scene
  std::string build_id;
  std::int64_t created_at_ms = 0;
  std::optional<std::int64_t> started_at_ms;
  std::optional<std::int64_t> finished_at_ms;
  JobProgress progress;
  std::string error_code;
  std::string error_message;
  // Sorted by name; filled for finished jobs.
  std::vector<std::pair<std::string, double>> metrics;
  double wall_time_s = 0.0;
};

}  // namespace seep::service
