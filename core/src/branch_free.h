// Tests that keep a loop free of branches, so that the compiler vectorises it (the coupled loop
// checks and selects over every pipe and domain at each flow update).
#pragma once

namespace seep::core::internal {

// x - x is 0 exactly for a finite x, and NaN for inf and NaN (std::isfinite would stop the
// vectoriser).
inline bool FiniteBranchFree(double x) { return x - x == 0.0; }

}  // namespace seep::core::internal
