// The effect registry: one Effect object per listed EffectSpec (core/src/effects/registry.cc).
#pragma once

#include <memory>
#include <vector>

#include "seep/core/effects/effect.h"
#include "seep/core/spec/effect_spec.h"

namespace seep::core {

std::unique_ptr<Effect> MakeEffect(const EffectSpec& spec);

// The effects of a (validated) list, in canonical order (the variant's arm order).
std::vector<std::unique_ptr<Effect>> MakeEffects(const std::vector<EffectSpec>& specs);

}  // namespace seep::core
