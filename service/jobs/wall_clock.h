// Wall-clock milliseconds since the Unix epoch: the time stamps the store records.
#pragma once

#include <chrono>
#include <cstdint>

namespace seep::service {

inline std::int64_t NowMs() {
  return std::chrono::duration_cast<std::chrono::milliseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

}  // namespace seep::service
