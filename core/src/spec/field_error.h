// The refusal every validator of the spec area returns: INVALID_ARGUMENT with the field's path
// first ("scene.stages[1].end[0].duration_s: must be ..."), which the CLI maps to a file line.
#pragma once

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "seep/core/status.h"

namespace seep::core::spec_internal {

inline Status Bad(const std::string& field, const std::string& why) {
  return InvalidArgument(fmt::format("{}: {}", field, why));
}

inline Status RequireFinite(const std::string& field, double value) {
  if (std::isfinite(value)) return Status::Ok();
  return Bad(field, fmt::format("must be finite (got {})", value));
}

}  // namespace seep::core::spec_internal
