#include "step_input.h"

#include <fmt/format.h>

#include <cmath>

#include "../branch_free.h"
#include "../parallel_threshold.h"

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
    // Every flow update: a branch-free count first; the scan that names one only on failure.
    const double* dv = volume_change.data();
    const auto n = static_cast<std::ptrdiff_t>(volume_change.size());
    // A count (exact in any order), so on the threads it is the same number.
    const double bad = internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
      double count = 0.0;
#pragma omp simd reduction(+ : count)
      for (std::ptrdiff_t d = begin; d < end; ++d) {
        count += internal::FiniteBranchFree(dv[d]) ? 0.0 : 1.0;
      }
      return count;
    });
    for (std::size_t d = 0; bad > 0.0 && d < volume_change.size(); ++d) {
      if (!std::isfinite(volume_change[d])) {
        return InvalidArgument(fmt::format("flow.{}.volume_change[{}]: must be finite (got {})",
                                           solver, d, FormatNumber(volume_change[d])));
      }
    }
  }
  return Status::Ok();
}

Status CheckTally(std::string_view solver, std::size_t num_nodes, const FluidTally* tally,
                  bool diagnostics) {
  if (tally == nullptr) return Status::Ok();
  if (!diagnostics) {
    return InvalidArgument(
        fmt::format("flow.{}.tally: needs the step's budget; switch diagnostics on", solver));
  }
  if (tally->node_outflow_m2.size() != num_nodes) {
    return InvalidArgument(fmt::format(
        "flow.{}.tally.node_outflow_m2: has {} entries, expected {} (one per flow node; Reset it)",
        solver, tally->node_outflow_m2.size(), num_nodes));
  }
  return Status::Ok();
}

}  // namespace seep::core::flow_internal
