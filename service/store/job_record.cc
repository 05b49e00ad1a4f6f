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

// A table's name for `value`, and the value of `name`: one spelling both ways.
template <typename Enum, std::size_t N>
const char* NameIn(const std::array<std::pair<Enum, const char*>, N>& names, Enum value) {
  for (const auto& [v, name] : names) {
    if (v == value) return name;
  }
  return "UNKNOWN";
}

template <typename Enum, std::size_t N>
std::optional<Enum> ParseIn(const std::array<std::pair<Enum, const char*>, N>& names,
                            std::string_view name) {
  for (const auto& [v, n] : names) {
    if (name == n) return v;
  }
  return std::nullopt;
}

}  // namespace

const char* JobKindName(JobKind kind) { return NameIn(kKindNames, kind); }

std::optional<JobKind> ParseJobKind(std::string_view name) { return ParseIn(kKindNames, name); }

const char* JobStateName(JobState state) { return NameIn(kNames, state); }

std::optional<JobState> ParseJobState(std::string_view name) { return ParseIn(kNames, name); }

}  // namespace seep::service
