// What one pressure step did: the step size actually taken, the explicit limit, and (when
// diagnostics are on) the fluid budget of the step.
//
// Mass balance of a step (docs/physics.md §1.2, R1, summed over non-fixed domains):
//   stored_change = sum_i V_s,i (P_i^{n+1} - P_i^n) / K_f                              [m^2]
//   expected      = dt (boundary_inflow + source_inflow) - volume_change                [m^2]
//   mass_balance_error = |stored_change - expected| / scale, relative to the stored excess fluid
//     sum V_s |P^{n+1}| / K_f plus the magnitudes of every term of the step: rounding of P itself
//     bounds what can be resolved, so near equilibrium the error is relative to the fluid held.
// Explicit steps evaluate boundary fluxes at the old pressures, backward Euler at the new ones:
// that is what each scheme actually transports.
#pragma once

#include <cstdint>
#include <limits>

namespace seep::core {

struct FlowStepReport {
  static constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

  double dt = 0.0;            // step taken, s (may be below the request under kReduce).
  double dt_requested = 0.0;  // s.
  double dt_crit = std::numeric_limits<double>::infinity();  // explicit limit (S1), s.
  std::int32_t limiting_domain = -1;
  bool limit_exceeded = false;  // explicit, advise-only policy: dt > safety * dt_crit was run.

  // Diagnostics; NaN when disabled.
  double boundary_inflow = kNaN;     // net rate into the network from fixed-pressure nodes, m^2/s.
  double source_inflow = kNaN;       // sum of Q_src over source domains, m^2/s.
  double volume_change = kNaN;       // sum of dV over non-fixed domains, m^2.
  double stored_change = kNaN;       // m^2, see above.
  double mass_balance_error = kNaN;  // relative, see above.
  double min_pressure = kNaN;        // Pa, over all domains after the step.
  double max_pressure = kNaN;
};

}  // namespace seep::core
