// Checks shared by the explicit and implicit steppers, and the number format of flow messages.
#pragma once

#include <cstddef>
#include <span>
#include <string>
#include <string_view>

#include "seep/core/flow/fluid_tally.h"
#include "seep/core/status.h"

namespace seep::core::flow_internal {

// "1.5e-07": six significant digits, as in every flow error message.
std::string FormatNumber(double value);

// dt must be finite and > 0; volume_change is empty or has one entry per domain, each finite
// when check_values is set. Messages name "flow.<solver>.dt" / "flow.<solver>.volume_change[i]".
Status CheckStepInput(std::string_view solver, double dt, std::size_t num_domains,
                      std::span<const double> volume_change, bool check_values);

// A tally (may be null) needs the step's budget, so diagnostics on, and one outflow entry per
// flow node. Messages name "flow.<solver>.tally".
Status CheckTally(std::string_view solver, std::size_t num_nodes, const FluidTally* tally,
                  bool diagnostics);

}  // namespace seep::core::flow_internal
