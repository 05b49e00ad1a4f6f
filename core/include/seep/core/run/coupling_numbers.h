// The dimensionless number that decides whether a coupled run's fluid stiffness is safe
// (issue 20, docs/accuracy.md "Coupled runs"): the fluid's storage stiffness K_f / n_s over the
// skeleton's bulk modulus K,
//   Pi_K = (K_f / n_s) / K.
// A load on a sealed skeleton is shared as du/dsigma = Pi_K / (1 + Pi_K) (docs/physics.md §3.4,
// V20), and Terzaghi's u0 and c_v carry the same factor, so a scaled-down K_f changes a coupled
// answer by about 1/Pi_K - 1/Pi_K(real water). The accuracy bench measured it on the undrained
// sample, the consolidation column and the hydraulic-fracturing initiation; below
// kSafeFluidToSkeletonStiffness the error against real water passed 5 %.
//
// Beside it, the flow interval: a pressure that lags the deformation by more than the step the
// fluid's stiffness allows is a delayed spring that pumps energy into the particles. The
// automatic interval stays within it; a fixed FlowEffectSpec::every_steps may not, and the bench's
// bonded sample then broke bonds within a few hundred steps at a few kPa. And the DEM step's
// safety factor, which a bonded sample in a stiff fluid needs at the default.
#pragma once

#include <optional>

#include "seep/core/effects/live_state.h"

namespace seep::core {

// From seep_accuracy_bench's coupled problems (docs/accuracy.md): above it every run at the
// automatic flow interval stayed within 5 % of real water. The undrained sample and the Terzaghi
// column alone allow 20 (3.8 % at Pi_K = 21); a fast injection does not: at Pi_K = 38 the
// initiation pressure was 5.8 % below real water's, because the scaled fluid pressurises the well
// more slowly and real water's own answer depends on the rate there.
inline constexpr double kSafeFluidToSkeletonStiffness = 50.0;

// The fluid-limited step over the flow interval (fluid_limited_dt / (every_steps dt_DEM)) below
// which a run's interval lags the fluid's stiffness: 1.
inline constexpr double kSafeFluidStepOverFlowInterval = 1.0;

// The DEM step safety (ContactsEffectSpec::dt_safety) up to which a bonded sample in real water
// is measured safe: seep_accuracy_bench --only breakdown runs its breakdown sample at K_f = 2.2e9
// with 0.2, 0.3, 0.4 and 0.5, and the initiation pressures agree within 1.6e-5. (With the pressure
// one step behind the forces, a delayed spring, the same sample broke bonds within a few hundred
// steps at 0.3 and above; effect.h says why.) Larger values are not measured, so a run reports
// them.
inline constexpr double kSafeBondedDemStepSafety = 0.5;

struct CouplingNumbers {
  double storage_porosity = 0.0;             // n_s = sum V_s / sum V_d over the stored domains
  double skeleton_bulk_modulus_pa = 0.0;     // K, the contacts' and bonds' affine estimate
  double fluid_to_skeleton_stiffness = 0.0;  // Pi_K
};

// For a coupled run (particles that move, a network, and fluid forces or the volume change on) on
// its current state; nullopt otherwise or when the state has no touching contact or no stored
// volume. K is the affine (uniform strain) estimate sum k_c l_c^2 / (4 A): k_c the contact law's
// kn for a touching pair plus a bond's kn_b 2 lambda min(R_i, R_j), l_c the centre distance, A the
// domains' apparent area. It is exact for a regular lattice's interior and an upper bound
// otherwise (a disordered packing relaxes below it), so Pi_K errs on the side of a warning.
std::optional<CouplingNumbers> MeasureCouplingNumbers(const LiveState& state);

}  // namespace seep::core
