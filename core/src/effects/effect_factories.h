// One factory per effect class that no other code holds a typed handle to (each defined beside
// its class); registry.cc maps the EffectSpec variant onto them and onto the classes with public
// headers (flow_effect.h, volume_change_effect.h).
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
std::unique_ptr<Effect> MakeApertureUpdateEffect(const ApertureUpdateEffectSpec& spec);
std::unique_ptr<Effect> MakeRedetectionEffect(const RedetectionEffectSpec& spec);
std::unique_ptr<Effect> MakeInjectionEffect(const InjectionEffectSpec& spec);

}  // namespace seep::core::effects_internal
