// Test only (seepd --test-crash-at POINT:N): the process kills itself with SIGKILL the N-th time
// it reaches a named point, so that the chaos test can crash seepd exactly where a random kill
// rarely lands. Off (no point armed) in production; seepd warns when one is armed.
#pragma once

#include <atomic>
#include <string>
#include <string_view>

#include "seep/core/status.h"

namespace seep::service {

class TestCrashPoints {
 public:
  // After a checkpoint file is written, before the store records it.
  static constexpr std::string_view kCheckpointFile = "checkpoint-file";
  // After a finished job's final state is made ready (its file written, when it gets one; a
  // worker process's uploaded), before its success is recorded.
  static constexpr std::string_view kFinalState = "final-state";

  // "POINT:N" (N >= 1); INVALID_ARGUMENT naming --test-crash-at otherwise.
  core::Status Arm(const std::string& spec);
  bool armed() const { return !point_.empty(); }
  const std::string& spec() const { return spec_; }
  // Counts a pass through `point`; the N-th pass of the armed point ends the process.
  void Reach(std::string_view point) const;

 private:
  std::string spec_;
  std::string point_;
  int nth_ = 0;
  mutable std::atomic<int> passes_{0};
};

}  // namespace seep::service
