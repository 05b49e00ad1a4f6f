// The dimensionless number that decides whether a coupled run's fluid stiffness is safe
// (issue 20, docs/accuracy.md "Coupled runs"): the fluid's storage stiffness K_f / n_s over the
// skeleton's bulk modulus K,
//   Pi_K = (K_f / n_s) / K.
// A load on a sealed skeleton is shared as du/dsigma = Pi_K / (1 + Pi_K) (physics.md §3.4, V20),
// and Terzaghi's u0 and c_v carry the same factor, so a scaled-down K_f changes a coupled answer by
// about 1/Pi_K - 1/Pi_K(real water). The accuracy bench measured it on the undrained sample and the
// consolidation column; below kSafeFluidToSkeletonStiffness the error against real water passed 5
// %.
#pragma once

#include <optional>

#include "seep/core/effects/live_state.h"

namespace seep::core {

// From seep_accuracy_bench's coupled problems (docs/accuracy.md): the smallest Pi_K at which
// every run of the undrained and the Terzaghi problems stayed within 5 % of real water.
inline constexpr double kSafeFluidToSkeletonStiffness = 20.0;

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
