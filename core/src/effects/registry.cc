// The effect registry: EffectSpec arm -> Effect object (docs/architecture.md §4).
//
// Adding an effect:
//   1. a spec struct in spec/effect_spec.h, placed in the variant where its hooks must run;
//   2. its class in core/src/effects/ (a factory in effect_factories.h, or a public header when
//      other code needs a typed handle to it, then a handle in EffectSet);
//   3. one arm below (a missing arm does not compile);
//   4. its name in EffectName (spec/effect_validation.cc), its checks in FieldValidator, and a
//      oneof arm in proto/seep/v1/scene.proto with its case in service/codec/effect_codec.cc.
#include <algorithm>

#include "effect_factories.h"
#include "seep/core/effects/effect_set.h"
#include "seep/core/effects/flow_effect.h"
#include "seep/core/effects/volume_change_effect.h"

namespace seep::core {
namespace {

template <class... Ts>
struct Overloaded : Ts... {
  using Ts::operator()...;
};
template <class... Ts>
Overloaded(Ts...) -> Overloaded<Ts...>;

// Makes the effect of one spec and fills its handle in *set.
std::unique_ptr<Effect> MakeEffect(const EffectSpec& spec, EffectSet* set) {
  using namespace effects_internal;  // NOLINT(google-build-using-namespace)
  const auto keep = [](std::unique_ptr<Effect> effect, const Effect** handle) {
    *handle = effect.get();
    return effect;
  };
  return std::visit(
      Overloaded{
          [&](const ContactsEffectSpec& s) { return keep(MakeContactsEffect(s), &set->contacts); },
          [](const BondsEffectSpec& s) { return MakeBondsEffect(s); },
          [](const GravityEffectSpec& s) { return MakeGravityEffect(s); },
          [&](const FluidForcesEffectSpec& s) {
            return keep(MakeFluidForcesEffect(s), &set->fluid_forces);
          },
          [](const LocalDampingEffectSpec& s) { return MakeLocalDampingEffect(s); },
          [](const WallsEffectSpec& s) { return MakeWallsEffect(s); },
          [&](const VolumeChangeEffectSpec&) -> std::unique_ptr<Effect> {
            auto effect = std::make_unique<VolumeChangeEffect>();
            set->volume_change = effect.get();
            return effect;
          },
          [](const ApertureUpdateEffectSpec& s) { return MakeApertureUpdateEffect(s); },
          [&](const FlowEffectSpec& s) -> std::unique_ptr<Effect> {
            auto effect = std::make_unique<FlowEffect>(s);
            set->flow = effect.get();
            return effect;
          },
          [](const RedetectionEffectSpec& s) { return MakeRedetectionEffect(s); },
          [&](const InjectionEffectSpec& s) {
            return keep(MakeInjectionEffect(s), &set->injection);
          },
      },
      spec);
}

}  // namespace

EffectSet MakeEffects(const std::vector<EffectSpec>& specs) {
  // Canonical order: by variant arm, whatever order the scene lists them in.
  std::vector<const EffectSpec*> sorted;
  sorted.reserve(specs.size());
  for (const EffectSpec& s : specs) sorted.push_back(&s);
  std::stable_sort(sorted.begin(), sorted.end(), [](const EffectSpec* a, const EffectSpec* b) {
    return a->index() < b->index();
  });
  EffectSet set;
  set.all.reserve(sorted.size());
  for (const EffectSpec* s : sorted) set.all.push_back(MakeEffect(*s, &set));
  return set;
}

}  // namespace seep::core
