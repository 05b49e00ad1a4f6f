// The effect registry: EffectSpec arm -> Effect object (design-anchors §5.4).
//
// Adding an effect:
//   1. a spec struct in effect_spec.h, placed in the variant where its hooks must run;
//   2. its class and factory in core/src/effects/ (declared in effect_factories.h);
//   3. one arm below (a missing arm does not compile);
//   4. its name in EffectName (effect_validation.cc), its checks in FieldValidator, and a oneof
//      arm in proto/seep/v1/scene.proto with its case in service/codec/scene_codec.cc.
#include "seep/core/effects/registry.h"

#include <algorithm>

#include "effect_factories.h"

namespace seep::core {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

}  // namespace

std::unique_ptr<Effect> MakeEffect(const EffectSpec& spec) {
  using namespace effects_internal;  // NOLINT(google-build-using-namespace)
  return std::visit(
      Overloaded{
          [](const ContactsEffectSpec& s) { return MakeContactsEffect(s); },
          [](const BondsEffectSpec& s) { return MakeBondsEffect(s); },
          [](const GravityEffectSpec& s) { return MakeGravityEffect(s); },
          [](const FluidForcesEffectSpec& s) { return MakeFluidForcesEffect(s); },
          [](const LocalDampingEffectSpec& s) { return MakeLocalDampingEffect(s); },
          [](const WallsEffectSpec& s) { return MakeWallsEffect(s); },
          [](const VolumeChangeEffectSpec& s) { return MakeVolumeChangeEffect(s); },
          [](const ApertureUpdateEffectSpec& s) { return MakeApertureUpdateEffect(s); },
          [](const FlowEffectSpec& s) { return MakeFlowEffect(s); },
          [](const RedetectionEffectSpec& s) { return MakeRedetectionEffect(s); },
          [](const InjectionEffectSpec& s) { return MakeInjectionEffect(s); },
      },
      spec);
}

std::vector<std::unique_ptr<Effect>> MakeEffects(const std::vector<EffectSpec>& specs) {
  // Canonical order: by variant arm, whatever order the scene lists them in.
  std::vector<const EffectSpec*> sorted;
  sorted.reserve(specs.size());
  for (const EffectSpec& s : specs) sorted.push_back(&s);
  std::stable_sort(sorted.begin(), sorted.end(), [](const EffectSpec* a, const EffectSpec* b) {
    return a->index() < b->index();
  });
  std::vector<std::unique_ptr<Effect>> effects;
  effects.reserve(sorted.size());
  for (const EffectSpec* s : sorted) effects.push_back(MakeEffect(*s));
  return effects;
}

}  // namespace seep::core
