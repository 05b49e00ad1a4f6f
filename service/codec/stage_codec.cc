#include "codec/stage_codec.h"

#include <fmt/format.h>

#include <optional>
#include <string>
#include <utility>

namespace seep::service {
namespace {

using core::InvalidArgument;

// A Setting the stage gives: unset leaves *out unset (the setting is kept from the stage before);
// a Setting message without value or schedule is refused, as it would look like a change.
core::Status SettingFromProto(bool given, const v1::Setting& setting, const std::string& path,
                              std::optional<core::SettingSpec>* out) {
  if (!given) return core::Status::Ok();
  switch (setting.kind_case()) {
    case v1::Setting::kValue:
      out->emplace(setting.value());
      return core::Status::Ok();
    case v1::Setting::kSchedule: {
      const v1::Schedule& s = setting.schedule();
      // Lengths and order are core's checks: it names the schedule's points.
      out->emplace(core::ScheduleSpec{{s.time_s().begin(), s.time_s().end()},
                                      {s.value().begin(), s.value().end()}});
      return core::Status::Ok();
    }
    case v1::Setting::KIND_NOT_SET:
      break;
  }
  return InvalidArgument(fmt::format(
      "{}: set one of value or schedule (leave the field out to keep the setting of the stage "
      "before)",
      path));
}

core::Status WallFromProto(const v1::StageWall& wall, const std::string& path,
                           core::StageWallSpec* out) {
  out->wall = wall.wall();
  switch (wall.mode_case()) {
    case v1::StageWall::kServoStressPa:
      SEEP_RETURN_IF_ERROR(SettingFromProto(true, wall.servo_stress_pa(), path + ".servo_stress_pa",
                                            &out->servo_stress_pa));
      break;
    case v1::StageWall::kNormalVelocityMS:
      SEEP_RETURN_IF_ERROR(SettingFromProto(true, wall.normal_velocity_m_s(),
                                            path + ".normal_velocity_m_s",
                                            &out->normal_velocity_m_s));
      break;
    case v1::StageWall::kFixed:
      out->fixed = wall.fixed();  // false, given explicitly, keeps the mode as unset does
      break;
    case v1::StageWall::MODE_NOT_SET:
      break;  // the wall keeps its mode and target
  }
  return SettingFromProto(wall.has_drain_pressure_pa(), wall.drain_pressure_pa(),
                          path + ".drain_pressure_pa", &out->drain_pressure_pa);
}

core::Status AppendEndFromProto(const v1::EndCondition& end, const std::string& path,
                                std::vector<core::EndConditionSpec>* out) {
  switch (end.kind_case()) {
    case v1::EndCondition::kDurationS:
      out->emplace_back(core::DurationEnd{end.duration_s()});
      return core::Status::Ok();
    case v1::EndCondition::kSteps:
      out->emplace_back(core::StepsEnd{end.steps()});
      return core::Status::Ok();
    case v1::EndCondition::kServoHeld:
      out->emplace_back(
          core::ServoHeldEnd{end.servo_held().tolerance_fraction(), end.servo_held().hold_s()});
      return core::Status::Ok();
    case v1::EndCondition::kKineticEnergyRatio:
      out->emplace_back(core::KineticEnergyEnd{end.kinetic_energy_ratio()});
      return core::Status::Ok();
    case v1::EndCondition::kBondsBroken:
      out->emplace_back(core::BondsBrokenEnd{end.bonds_broken()});
      return core::Status::Ok();
    case v1::EndCondition::kBreakthrough:
      // The arm is a flag only so that the text format can name it; false would be a condition
      // that never holds, which is surely a mistake.
      if (!end.breakthrough()) {
        return InvalidArgument(
            fmt::format("{}.breakthrough: must be true (remove the end condition to not end on a "
                        "breakthrough)",
                        path));
      }
      out->emplace_back(core::BreakthroughEnd{});
      return core::Status::Ok();
    case v1::EndCondition::kWellPressurePastPeak:
      out->emplace_back(core::WellPressurePastPeakEnd{end.well_pressure_past_peak()});
      return core::Status::Ok();
    case v1::EndCondition::KIND_NOT_SET:
      break;
  }
  return InvalidArgument(
      fmt::format("{}: set one end condition (duration_s, steps, servo_held, kinetic_energy_ratio, "
                  "bonds_broken, breakthrough, well_pressure_past_peak)",
                  path));
}

}  // namespace

core::Status AppendStageFromProto(const v1::Stage& stage, std::size_t index,
                                  std::vector<core::StageSpec>* out) {
  const std::string path = fmt::format("scene.stages[{}]", index);
  core::StageSpec spec;
  spec.name = stage.name();
  struct SettingField {
    const char* name;
    bool given;
    const v1::Setting& setting;
    std::optional<core::SettingSpec>* target;
  };
  const SettingField settings[] = {{"injection_rate_m2_s", stage.has_injection_rate_m2_s(),
                                    stage.injection_rate_m2_s(), &spec.injection_rate_m2_s},
                                   {"inlet_pressure_pa", stage.has_inlet_pressure_pa(),
                                    stage.inlet_pressure_pa(), &spec.inlet_pressure_pa},
                                   {"outlet_pressure_pa", stage.has_outlet_pressure_pa(),
                                    stage.outlet_pressure_pa(), &spec.outlet_pressure_pa},
                                   {"well_pressure_pa", stage.has_well_pressure_pa(),
                                    stage.well_pressure_pa(), &spec.well_pressure_pa},
                                   {"outer_pressure_pa", stage.has_outer_pressure_pa(),
                                    stage.outer_pressure_pa(), &spec.outer_pressure_pa}};
  for (const SettingField& f : settings) {
    SEEP_RETURN_IF_ERROR(SettingFromProto(f.given, f.setting, path + "." + f.name, f.target));
  }
  if (stage.has_local_damping_alpha()) spec.local_damping_alpha = stage.local_damping_alpha();
  spec.walls.resize(static_cast<std::size_t>(stage.walls_size()));
  for (int k = 0; k < stage.walls_size(); ++k) {
    SEEP_RETURN_IF_ERROR(WallFromProto(stage.walls(k), fmt::format("{}.walls[{}]", path, k),
                                       &spec.walls[static_cast<std::size_t>(k)]));
  }
  spec.regions.resize(static_cast<std::size_t>(stage.regions_size()));
  for (int k = 0; k < stage.regions_size(); ++k) {
    const v1::StageRegion& region = stage.regions(k);
    core::StageRegionSpec& target = spec.regions[static_cast<std::size_t>(k)];
    target.region = region.region();
    SEEP_RETURN_IF_ERROR(SettingFromProto(region.has_value(), region.value(),
                                          fmt::format("{}.regions[{}].value", path, k),
                                          &target.value));
  }
  for (int k = 0; k < stage.end_size(); ++k) {
    SEEP_RETURN_IF_ERROR(
        AppendEndFromProto(stage.end(k), fmt::format("{}.end[{}]", path, k), &spec.end));
  }
  spec.max_duration_s = stage.max_duration_s();
  spec.continue_at_max_duration = stage.continue_at_max_duration();
  out->push_back(std::move(spec));
  return core::Status::Ok();
}

}  // namespace seep::service
