// EffectSet: the effects a scene lists, made from their specs in canonical order (the EffectSpec
// variant's arm order), with typed handles to the ones that other effects or the step loop talk
// to. A handle is null when its effect is not listed; nothing looks an effect up by name.
#pragma once

#include <memory>
#include <vector>

#include "seep/core/effects/effect.h"
#include "seep/core/spec/effect_spec.h"

namespace seep::core {

class FlowEffect;
class VolumeChangeEffect;

struct EffectSet {
  std::vector<std::unique_ptr<Effect>> all;  // canonical order
  const Effect* contacts = nullptr;
  const Effect* fluid_forces = nullptr;
  const Effect* injection = nullptr;
  VolumeChangeEffect* volume_change = nullptr;
  FlowEffect* flow = nullptr;
};

// The effects of a (validated) list; the registry (core/src/effects/registry.cc) maps each arm.
EffectSet MakeEffects(const std::vector<EffectSpec>& specs);

}  // namespace seep::core
