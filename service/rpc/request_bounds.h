// Bounds on the ids and names a request carries, checked before any look-up: an id longer than
// any seepd makes is refused without being echoed (a 16 KB id echoed into the error overflowed
// the client's metadata), and a name is held to what a log line and a listing can show.
#pragma once

#include <fmt/format.h>

#include <cstddef>
#include <string_view>

#include "seep/core/status.h"

namespace seep::service {

// Every id seepd makes is 18 characters ("j-" and 16 hex digits); 64 leaves room for other
// forms without letting an id grow into a payload.
inline constexpr std::size_t kMaxIdLength = 64;
// A job's, sweep's or calibration's name.
inline constexpr std::size_t kMaxNameLength = 200;

// INVALID_ARGUMENT "<field>: ..." for an id past kMaxIdLength; only its length is echoed.
inline core::Status CheckIdLength(std::string_view id, std::string_view field) {
  if (id.size() <= kMaxIdLength) return core::Status::Ok();
  return core::InvalidArgument(
      fmt::format("{}: at most {} characters (got {}); seepd's ids look like j-0123456789abcdef",
                  field, kMaxIdLength, id.size()));
}

// INVALID_ARGUMENT "<field>: ..." for a name past kMaxNameLength.
inline core::Status CheckNameLength(std::string_view name, std::string_view field) {
  if (name.size() <= kMaxNameLength) return core::Status::Ok();
  return core::InvalidArgument(
      fmt::format("{}: at most {} characters (got {})", field, kMaxNameLength, name.size()));
}

}  // namespace seep::service
