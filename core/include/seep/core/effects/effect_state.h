// The persisted part of each effect that keeps run totals of its own: what it saves into a
// snapshot and restores from one (Effect::SaveTo / RestoreFrom). An effect that is not listed
// leaves its part at these defaults. Adding a persisted field touches the effect, its part here
// and its codec (service/codec/mechanics_state_codec.cc) only.
#pragma once

#include <cstdint>

namespace seep::core {

struct ContactsEffectState {
  std::uint64_t bonds_broken = 0;
  // Moments of the broken bonds' midpoints where they broke (their count, sums of x, y, xx, xy,
  // yy): the fracture's trace and orientation (its principal axis) without keeping every break.
  std::uint64_t broken_traced = 0;
  double broken_x = 0.0, broken_y = 0.0;
  double broken_xx = 0.0, broken_xy = 0.0, broken_yy = 0.0;
};

struct FlowEffectState {
  std::int64_t max_sub_steps = 0;  // most flow sub-steps in one flow update
  // The critical step and its domain as the last flow update found them (moving scenes; the
  // metrics dt_crit_s and limiting_domain). 0: none kept (an older checkpoint), the re-bind's.
  double dt_crit_s = 0.0;
  std::int32_t limiting_domain = -1;
};

struct RedetectionEffectState {
  double breakthrough_time_s = -1.0;  // when a fracture first opened the well to the outside
  std::uint64_t redetections = 0;     // networks rebuilt since the run began (metric redetections)
};

struct InjectionEffectState {
  double peak_well_pressure_pa = 0.0;  // the breakdown pressure once the well pressure falls
  double peak_well_time_s = 0.0;
};

struct EffectStates {
  ContactsEffectState contacts;
  FlowEffectState flow;
  RedetectionEffectState redetection;
  InjectionEffectState injection;
};

}  // namespace seep::core
