// One factory per effect class (each defined beside its class); registry.cc maps the EffectSpec
// variant onto them.
#pragma once

#include <memory>

#include "seep/core/effects/effect.h"
#include "seep/core/spec/effect_spec.h"

namespace seep::core::effects_internal {

std::unique_ptr<Effect> MakeContactsEffect(const ContactsEffectSpec& spec);
std::unique_ptr<Effect> MakeBondsEffect(const BondsEffectSpec& spec);
std::unique_ptr<Effect> MakeGravityEffect(const GravityEffectSpec& spec);
std::unique_ptr<Effect> MakeFluidForcesEffect(const FluidForcesEffectSpec& spec);
std::unique_ptr<Effect> MakeLocalDampingEffect(const LocalDampingEffectSpec& spec);
std::unique_ptr<Effect> MakeWallsEffect(const WallsEffectSpec& spec);
std::unique_ptr<Effect> MakeVolumeChangeEffect(const VolumeChangeEffectSpec& spec);
std::unique_ptr<Effect> MakeApertureUpdateEffect(const ApertureUpdateEffectSpec& spec);
std::unique_ptr<Effect> MakeFlowEffect(const FlowEffectSpec& spec);
std::unique_ptr<Effect> MakeRedetectionEffect(const RedetectionEffectSpec& spec);
std::unique_ptr<Effect> MakeInjectionEffect(const InjectionEffectSpec& spec);

}  // namespace seep::core::effects_internal

namespace seep::core::effects_internal {
// The DEM step the fluid's stiffness allows when pressure follows deformation (volume_change with
// fluid_forces): a particle on a chord c of domain d pushed by delta changes V_d by c delta, the
// pressure by K_f c delta / V_s and its force by K_f c^2 delta / V_s, a spring of stiffness
// k_f = sum over its domains of K_f c^2 / V_s. Returns safety * min_i sqrt(m_i / k_f,i).
double FluidStableStep(const CoupledState& state, double safety);

// DEM steps per flow update of a bound flow effect.
std::uint64_t FlowEverySteps(const Effect& flow, const CoupledState& state);
}  // namespace seep::core::effects_internal
