// The DEM step the fluid's stiffness allows when pressure follows deformation (volume_change with
// fluid_forces): a particle on a chord c of domain d pushed by delta changes V_d by c delta, the
// pressure by K_f c delta / V_s and its force by K_f c^2 delta / V_s, a spring of stiffness
// k_f = sum over its domains of K_f c^2 / V_s.
#pragma once

#include "seep/core/effects/live_state.h"

namespace seep::core {

// safety * min_i sqrt(m_i / k_f,i); inf when no particle bounds a free domain.
double FluidStableStep(const LiveState& state, double safety);

}  // namespace seep::core
