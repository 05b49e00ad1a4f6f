#include "job_record.h"

#include <array>

namespace seep::service {
namespace {
constexpr std::array<std::pair<JobState, const char*>, 5> kNames = {{
    {JobState::kQueued, "QUEUED"},
    {JobState::kRunning, "RUNNING"},
    {JobState::kSucceeded, "SUCCEEDED"},
    {JobState::kFailed, "FAILED"},
    {JobState::kCancelled, "CANCELLED"},
}};

constexpr std::array<std::pair<JobKind, const char*>, 2> kKindNames = {{
    {JobKind::kSimulation, "SIMULATION"},
    {JobKind::kCalibration, "CALIBRATION"},
}};
}  // namespace

const char* JobKindName(JobKind kind) {
  for (const auto& [k, name] : kKindNames) {
    if (k == kind) return name;
  }
  return "UNKNOWN";
}

std::optional<JobKind> ParseJobKind(std::string_view name) {
  for (const auto& [k, n] : kKindNames) {
    if (name == n) return k;
  }
  return std::nullopt;
}

const char* JobStateName(JobState state) {
  for (const auto& [s, name] : kNames) {
    if (s == state) return name;
  }
  return "UNKNOWN";
}

std::optional<JobState> ParseJobState(std::string_view name) {
  for (const auto& [s, n] : kNames) {
    if (name == n) return s;
  }
  return std::nullopt;
}

}  // namespace seep::service
