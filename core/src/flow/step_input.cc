#include "step_input.h"

#include <fmt/format.h>

#include <cmath>

namespace seep::core::flow_internal {

std::string FormatNumber(double value) { return fmt::format("{:.6g}", value); }

Status CheckStepInput(std::string_view solver, double dt, std::size_t num_domains,
                      std::span<const double> volume_change, bool check_values) {
  if (!(std::isfinite(dt) && dt > 0.0)) {
    return InvalidArgument(
        fmt::format("flow.{}.dt: must be finite and > 0 (got {})", solver, FormatNumber(dt)));
  }
  if (!volume_change.empty() && volume_change.size() != num_domains) {
    return InvalidArgument(
        fmt::format("flow.{}.volume_change: has {} entries, expected {} (one per domain, or none)",
                    solver, volume_change.size(), num_domains));
  }
  if (check_values) {
    for (std::size_t d = 0; d < volume_change.size(); ++d) {
      if (!std::isfinite(volume_change[d])) {
        return InvalidArgument(fmt::format("flow.{}.volume_change[{}]: must be finite (got {})",
                                           solver, d, FormatNumber(volume_change[d])));
      }
    }
  }
  return Status::Ok();
}

}  // namespace seep::core::flow_internal
