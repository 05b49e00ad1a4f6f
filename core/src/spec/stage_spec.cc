#include "seep/core/spec/stage_spec.h"

#include <algorithm>
#include <type_traits>

namespace seep::core {

double SettingAt(const SettingSpec& setting, double t) {
  if (const double* value = std::get_if<double>(&setting)) return *value;
  const ScheduleSpec& s = std::get<ScheduleSpec>(setting);
  if (t <= s.time_s.front()) return s.value.front();
  if (t >= s.time_s.back()) return s.value.back();
  // The first point after t: t lies in [time_s[k - 1], time_s[k]).
  const auto after = std::upper_bound(s.time_s.begin(), s.time_s.end(), t);
  const auto k = static_cast<std::size_t>(after - s.time_s.begin());
  const double t0 = s.time_s[k - 1], t1 = s.time_s[k];
  const double w = (t - t0) / (t1 - t0);
  return s.value[k - 1] + w * (s.value[k] - s.value[k - 1]);
}

double SettingEnd(const SettingSpec& setting) {
  if (const double* value = std::get_if<double>(&setting)) return *value;
  return std::get<ScheduleSpec>(setting).value.back();
}

const char* EndConditionName(const EndConditionSpec& condition) {
  return std::visit(
      [](const auto& c) -> const char* {
        using T = std::decay_t<decltype(c)>;
        if constexpr (std::is_same_v<T, DurationEnd>) return "duration_s";
        if constexpr (std::is_same_v<T, StepsEnd>) return "steps";
        if constexpr (std::is_same_v<T, ServoHeldEnd>) return "servo_held";
        if constexpr (std::is_same_v<T, KineticEnergyEnd>) return "kinetic_energy_ratio";
        if constexpr (std::is_same_v<T, BondsBrokenEnd>) return "bonds_broken";
        if constexpr (std::is_same_v<T, BreakthroughEnd>) return "breakthrough";
        if constexpr (std::is_same_v<T, WellPressurePastPeakEnd>) return "well_pressure_past_peak";
      },
      condition);
}

bool HasSchedule(const StageSpec& stage) {
  const auto scheduled = [](const std::optional<SettingSpec>& setting) {
    return setting && std::holds_alternative<ScheduleSpec>(*setting);
  };
  bool any = scheduled(stage.injection_rate_m2_s) || scheduled(stage.inlet_pressure_pa) ||
             scheduled(stage.outlet_pressure_pa) || scheduled(stage.well_pressure_pa) ||
             scheduled(stage.outer_pressure_pa);
  for (const StageWallSpec& w : stage.walls) {
    any = any || scheduled(w.servo_stress_pa) || scheduled(w.normal_velocity_m_s) ||
          scheduled(w.drain_pressure_pa);
  }
  for (const StageRegionSpec& r : stage.regions) any = any || scheduled(r.value);
  return any;
}

}  // namespace seep::core
