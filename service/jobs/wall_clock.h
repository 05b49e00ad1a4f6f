// Wall-clock milliseconds since the Unix epoch: the time stamps the store records; and a cheap
// reading of the steady clock for checks made at every step.
#pragma once

#include <time.h>

#include <chrono>
#include <cstdint>

namespace seep::service {

inline std::int64_t NowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

// std::chrono::steady_clock's clock (CLOCK_MONOTONIC) as the kernel last ticked it: behind
// steady_clock::now() by at most a tick (1 to 10 ms), and read without the clock source. A fine
// read costs up to a microsecond on a virtual machine whose clock is not the TSC: as a per-step
// check it took 1 % of a small scene's run.
inline std::chrono::steady_clock::time_point CoarseSteadyNow() {
  timespec ts{};
  ::clock_gettime(CLOCK_MONOTONIC_COARSE, &ts);
  return std::chrono::steady_clock::time_point(
      std::chrono::duration_cast<std::chrono::steady_clock::duration>(
          std::chrono::seconds(ts.tv_sec) + std::chrono::nanoseconds(ts.tv_nsec)));
}

}  // namespace seep::service
