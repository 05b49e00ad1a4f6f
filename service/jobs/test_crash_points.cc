#include "jobs/test_crash_points.h"

#include <fmt/format.h>
#include <signal.h>
#include <unistd.h>

namespace seep::service {

core::Status TestCrashPoints::Arm(const std::string& spec) {
  const auto colon = spec.rfind(':');
  const std::string point = spec.substr(0, colon);
  int nth = 0;
  if (colon != std::string::npos) {
    try {
      std::size_t used = 0;
      nth = std::stoi(spec.substr(colon + 1), &used);
      if (used != spec.size() - colon - 1) nth = 0;
    } catch (const std::exception&) {
      nth = 0;
    }
  }
  if ((point != kCheckpointFile && point != kFinalState) || nth < 1) {
    return core::InvalidArgument(
        fmt::format("--test-crash-at: '{}' is not POINT:N with POINT {} or {} and N >= 1", spec,
                    kCheckpointFile, kFinalState));
  }
  spec_ = spec;
  point_ = point;
  nth_ = nth;
  return core::Status::Ok();
}

void TestCrashPoints::Reach(std::string_view point) const {
  if (point != point_) return;
  if (passes_.fetch_add(1) + 1 == nth_) {
    // Unflushed log lines may be lost, as they would in a real crash.
    ::kill(::getpid(), SIGKILL);
    ::pause();
  }
}

}  // namespace seep::service
