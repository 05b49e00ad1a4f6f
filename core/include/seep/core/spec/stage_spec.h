// StageSpec: one stage of an experiment (confine, inject, shut in, shear, ...). A scene with
// stages runs them in order in one job; each stage may change settings at its start (or follow a
// schedule over its own time) and ends on the first of its end conditions that holds.
//
// Settings a stage leaves unset keep what the stage before it left (a schedule's last value).
// The scene's own fields are the settings before the first stage. Stage time counts from the
// stage's start.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

namespace seep::core {

// A piecewise-linear table over stage time: linear between its points, the first value before
// the first point and the last value after the last. Times strictly increasing, the first >= 0.
struct ScheduleSpec {
  std::vector<double> time_s;
  std::vector<double> value;
};

// A stage setting: a constant from the stage's start, or a schedule over stage time.
using SettingSpec = std::variant<double, ScheduleSpec>;

// The value of a setting at stage time t.
double SettingAt(const SettingSpec& setting, double t);
// The value it ends on (what the next stage keeps when it leaves the setting unset).
double SettingEnd(const SettingSpec& setting);

// How a stage drives one wall of the walls effect (by its index there). A mode left unset keeps
// the wall's mode and target; `fixed` stops it where it is.
struct StageWallSpec {
  std::uint32_t wall = 0;
  std::optional<SettingSpec> servo_stress_pa;      // servo on this stress (> 0)
  std::optional<SettingSpec> normal_velocity_m_s;  // velocity-controlled (strain-controlled)
  bool fixed = false;                              // neither: the wall stands still
  std::optional<SettingSpec> drain_pressure_pa;    // a drained wall's platen pressure
};

// Replaces boundary region `region`'s (its index in boundary.regions) pressure_pa or rate_m2_s,
// whichever its condition is; unset keeps it.
struct StageRegionSpec {
  std::uint32_t region = 0;
  std::optional<SettingSpec> value;
};

// End conditions; a stage ends at the first step (for scenes with flow: the first flow update,
// so that the stage's last step closes the fluid's books) at which one of its conditions holds.
struct DurationEnd {
  double duration_s = 0.0;  // stage time reached
};
struct StepsEnd {
  std::uint64_t steps = 0;  // steps taken in the stage
};
// Every servo wall within tolerance_fraction x its target stress for hold_s of stage time.
struct ServoHeldEnd {
  double tolerance_fraction = 0.0;
  double hold_s = 0.0;
};
// The particles' kinetic energy (translation + rotation) at most ratio x its peak in the stage.
struct KineticEnergyEnd {
  double ratio = 0.0;
};
// At least `count` bonds broken in the stage.
struct BondsBrokenEnd {
  std::uint64_t count = 0;
};
// The fracture opened the well to the outer boundary (radial scenes with re-detection).
struct BreakthroughEnd {};
// The well pressure fell to (1 - fraction) x its peak in the stage (the breakdown is behind).
struct WellPressurePastPeakEnd {
  double fraction = 0.0;
};

using EndConditionSpec = std::variant<DurationEnd, StepsEnd, ServoHeldEnd, KineticEnergyEnd,
                                      BondsBrokenEnd, BreakthroughEnd, WellPressurePastPeakEnd>;

// The name a scene file uses for a condition's arm (e.g. "servo_held").
const char* EndConditionName(const EndConditionSpec& condition);

struct StageSpec {
  std::string name;
  // Settings (unset: kept from the stage before).
  std::optional<SettingSpec> injection_rate_m2_s;  // >= 0; 0 shuts the well in
  std::optional<double> local_damping_alpha;       // [0, 1)
  std::optional<SettingSpec> inlet_pressure_pa;
  std::optional<SettingSpec> outlet_pressure_pa;
  std::optional<SettingSpec> well_pressure_pa;
  std::optional<SettingSpec> outer_pressure_pa;
  std::vector<StageWallSpec> walls;
  // The stage ends when any of these holds.
  std::vector<EndConditionSpec> end;
  // Stage time after which the stage fails the run (or, with continue_at_max_duration, moves on
  // to the next stage); 0 = none, allowed only when a duration or steps condition bounds it.
  double max_duration_s = 0.0;
  bool continue_at_max_duration = false;
  // Boundary regions' pressures or rates (after the fields above, which code may list in order).
  std::vector<StageRegionSpec> regions;
};

// Whether any of the stage's settings follows a schedule (else they are constant over it).
bool HasSchedule(const StageSpec& stage);

}  // namespace seep::core
