// Validation of a scene's stages: each stage's settings against the effects and boundary the
// scene has, its end conditions against the effects they watch, and that every stage ends.
#include <fmt/format.h>

#include <cmath>
#include <string>
#include <type_traits>
#include <vector>

#include "field_error.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {
namespace {

using spec_internal::Bad;

// What a setting's values may be.
enum class Range { kFinite, kNonNegative, kPositive, kUnitInterval };

bool InRange(double v, Range range) {
  if (!std::isfinite(v)) return false;
  switch (range) {
    case Range::kFinite:
      return true;
    case Range::kNonNegative:
      return v >= 0.0;
    case Range::kPositive:
      return v > 0.0;
    case Range::kUnitInterval:
      return v >= 0.0 && v < 1.0;
  }
  return false;
}

const char* RangeText(Range range) {
  switch (range) {
    case Range::kFinite:
      return "must be finite";
    case Range::kNonNegative:
      return "must be a finite number >= 0";
    case Range::kPositive:
      return "must be a finite number > 0";
    case Range::kUnitInterval:
      return "must lie in [0, 1)";
  }
  return "";
}

// A constant in range, or a schedule: as many values as times, times finite, the first >= 0,
// strictly increasing, every value in range.
Status ValidateSetting(const std::string& field, const SettingSpec& setting, Range range) {
  if (const double* value = std::get_if<double>(&setting)) {
    if (!InRange(*value, range)) {
      return Bad(field + ".value", fmt::format("{} (got {})", RangeText(range), *value));
    }
    return Status::Ok();
  }
  const ScheduleSpec& s = std::get<ScheduleSpec>(setting);
  const std::string schedule = field + ".schedule";
  if (s.time_s.empty()) {
    return Bad(schedule + ".time_s", "a schedule needs at least one point");
  }
  if (s.value.size() != s.time_s.size()) {
    return Bad(schedule + ".value", fmt::format("{} values for {} times (one value per time)",
                                                s.value.size(), s.time_s.size()));
  }
  for (std::size_t k = 0; k < s.time_s.size(); ++k) {
    const double t = s.time_s[k];
    if (!std::isfinite(t) || t < 0.0) {
      return Bad(fmt::format("{}.time_s[{}]", schedule, k),
                 fmt::format("must be a finite stage time >= 0 (got {})", t));
    }
    if (k > 0 && !(t > s.time_s[k - 1])) {
      return Bad(fmt::format("{}.time_s[{}]", schedule, k),
                 fmt::format("must be greater than time_s[{}] (a schedule is increasing in "
                             "time; got {} after {})",
                             k - 1, t, s.time_s[k - 1]));
    }
    if (!InRange(s.value[k], range)) {
      return Bad(fmt::format("{}.value[{}]", schedule, k),
                 fmt::format("{} (got {})", RangeText(range), s.value[k]));
    }
  }
  return Status::Ok();
}

class StageValidator {
 public:
  explicit StageValidator(const SceneSpec& scene)
      : scene_(scene), walls_(FindEffect<WallsEffectSpec>(scene)) {
    if (walls_ != nullptr) {
      for (const WallSpec& w : walls_->walls) servo_.push_back(w.servo_stress_pa > 0.0);
    }
  }

  Status Validate(std::size_t i, const StageSpec& stage) {
    const std::string at = fmt::format("scene.stages[{}]", i);
    SEEP_RETURN_IF_ERROR(ValidateSettings(at, stage));
    SEEP_RETURN_IF_ERROR(ValidateWalls(at, stage));
    SEEP_RETURN_IF_ERROR(ValidateRegions(at, stage));
    return ValidateEnds(at, stage);
  }

 private:
  Status Requires(const std::string& field, bool listed, const char* effect) const {
    if (listed) return Status::Ok();
    return Bad(field, fmt::format("the scene does not list the {} effect", effect));
  }

  Status ValidateSettings(const std::string& at, const StageSpec& stage) const {
    const BoundarySpec& b = scene_.boundary;
    const bool linear = !b.radial && !b.walls_only;
    const bool injected = HasEffect<InjectionEffectSpec>(scene_);
    if (const auto& rate = stage.injection_rate_m2_s) {
      const std::string field = at + ".injection_rate_m2_s";
      SEEP_RETURN_IF_ERROR(Requires(field, injected, "injection"));
      SEEP_RETURN_IF_ERROR(ValidateSetting(field, *rate, Range::kNonNegative));
    }
    if (const auto& alpha = stage.local_damping_alpha) {
      const std::string field = at + ".local_damping_alpha";
      SEEP_RETURN_IF_ERROR(
          Requires(field, HasEffect<LocalDampingEffectSpec>(scene_), "local_damping"));
      if (!InRange(*alpha, Range::kUnitInterval)) {
        return Bad(field, fmt::format("must lie in [0, 1) (got {})", *alpha));
      }
    }
    struct Pressure {
      const char* name;
      const std::optional<SettingSpec>& setting;
      bool applies;
      const char* why;
    };
    const Pressure pressures[] = {
        {"inlet_pressure_pa", stage.inlet_pressure_pa, linear && !b.closed_inlet,
         "needs a linear boundary with an open inlet"},
        {"outlet_pressure_pa", stage.outlet_pressure_pa, linear, "needs a linear boundary"},
        {"well_pressure_pa", stage.well_pressure_pa, b.radial && !injected,
         injected ? "the well is injected (injection effect): set injection_rate_m2_s"
                  : "needs a radial boundary"},
        {"outer_pressure_pa", stage.outer_pressure_pa, b.radial.has_value(),
         "needs a radial boundary"},
    };
    for (const Pressure& p : pressures) {
      if (!p.setting) continue;
      const std::string field = fmt::format("{}.{}", at, p.name);
      SEEP_RETURN_IF_ERROR(Requires(field, HasFlow(scene_), "flow"));
      if (!p.applies) return Bad(field, p.why);
      SEEP_RETURN_IF_ERROR(ValidateSetting(field, *p.setting, Range::kFinite));
    }
    return Status::Ok();
  }

  // Also updates which walls are servo walls from this stage on.
  Status ValidateWalls(const std::string& at, const StageSpec& stage) {
    std::vector<bool> seen(servo_.size(), false);
    for (std::size_t j = 0; j < stage.walls.size(); ++j) {
      const StageWallSpec& w = stage.walls[j];
      const std::string field = fmt::format("{}.walls[{}]", at, j);
      SEEP_RETURN_IF_ERROR(Requires(field, walls_ != nullptr, "walls"));
      if (w.wall >= servo_.size()) {
        return Bad(field + ".wall", fmt::format("the walls effect has {} walls (got index {})",
                                                servo_.size(), w.wall));
      }
      if (seen[w.wall]) {
        return Bad(field + ".wall", fmt::format("wall {} is listed twice in this stage", w.wall));
      }
      seen[w.wall] = true;
      const WallSpec& spec = walls_->walls[w.wall];
      const int modes =
          (w.servo_stress_pa ? 1 : 0) + (w.normal_velocity_m_s ? 1 : 0) + (w.fixed ? 1 : 0);
      if (modes > 1) {
        return Bad(field, "set one of servo_stress_pa, normal_velocity_m_s and fixed");
      }
      if (w.servo_stress_pa) {
        SEEP_RETURN_IF_ERROR(
            ValidateSetting(field + ".servo_stress_pa", *w.servo_stress_pa, Range::kPositive));
        if (!(std::isfinite(spec.servo_max_speed_m_s) && spec.servo_max_speed_m_s > 0.0)) {
          return Bad(field + ".servo_stress_pa",
                     fmt::format("wall {} of the walls effect has no servo_max_speed_m_s > 0, "
                                 "which a servo needs (set it there)",
                                 w.wall));
        }
        servo_[w.wall] = true;
      }
      if (w.normal_velocity_m_s) {
        SEEP_RETURN_IF_ERROR(ValidateSetting(field + ".normal_velocity_m_s", *w.normal_velocity_m_s,
                                             Range::kFinite));
        servo_[w.wall] = false;
      }
      if (w.fixed) servo_[w.wall] = false;
      if (w.drain_pressure_pa) {
        if (!spec.drain) {
          return Bad(field + ".drain_pressure_pa",
                     fmt::format("wall {} is not drained (its drain is unset)", w.wall));
        }
        SEEP_RETURN_IF_ERROR(
            ValidateSetting(field + ".drain_pressure_pa", *w.drain_pressure_pa, Range::kFinite));
      }
    }
    return Status::Ok();
  }

  // Each region by its index in boundary.regions, once per stage; any finite pressure or rate.
  Status ValidateRegions(const std::string& at, const StageSpec& stage) const {
    const std::size_t count = scene_.boundary.regions.size();
    std::vector<bool> seen(count, false);
    for (std::size_t j = 0; j < stage.regions.size(); ++j) {
      const StageRegionSpec& r = stage.regions[j];
      const std::string field = fmt::format("{}.regions[{}]", at, j);
      if (r.region >= count) {
        return Bad(
            field + ".region",
            fmt::format("the scene has {} boundary regions (got index {})", count, r.region));
      }
      if (seen[r.region]) {
        return Bad(field + ".region",
                   fmt::format("region {} is listed twice in this stage", r.region));
      }
      seen[r.region] = true;
      if (r.value)
        SEEP_RETURN_IF_ERROR(ValidateSetting(field + ".value", *r.value, Range::kFinite));
    }
    return Status::Ok();
  }

  Status ValidateEnds(const std::string& at, const StageSpec& stage) const {
    if (stage.end.empty()) {
      return Bad(at + ".end", "a stage needs at least one end condition");
    }
    bool bounded = false;
    std::vector<bool> kinds(std::variant_size_v<EndConditionSpec>, false);
    for (std::size_t k = 0; k < stage.end.size(); ++k) {
      const std::string field = fmt::format("{}.end[{}].{}", at, k, EndConditionName(stage.end[k]));
      if (kinds[stage.end[k].index()]) {
        return Bad(field, "this condition is listed twice in the stage (once each)");
      }
      kinds[stage.end[k].index()] = true;
      const Status checked = std::visit(
          [&](const auto& c) -> Status {
            using T = std::decay_t<decltype(c)>;
            if constexpr (std::is_same_v<T, DurationEnd>) {
              bounded = true;
              if (!InRange(c.duration_s, Range::kPositive)) {
                return Bad(field,
                           fmt::format("must be a finite number > 0 (got {})", c.duration_s));
              }
            } else if constexpr (std::is_same_v<T, StepsEnd>) {
              bounded = true;
              if (c.steps == 0) return Bad(field, "must be >= 1");
            } else if constexpr (std::is_same_v<T, ServoHeldEnd>) {
              if (!(std::isfinite(c.tolerance_fraction) && c.tolerance_fraction > 0.0 &&
                    c.tolerance_fraction < 1.0)) {
                return Bad(field + ".tolerance_fraction",
                           fmt::format("must lie in (0, 1) (got {})", c.tolerance_fraction));
              }
              if (!InRange(c.hold_s, Range::kNonNegative)) {
                return Bad(field + ".hold_s",
                           fmt::format("must be a finite number >= 0 (got {})", c.hold_s));
              }
              SEEP_RETURN_IF_ERROR(Requires(field, walls_ != nullptr, "walls"));
              bool any = false;
              for (const bool s : servo_) any = any || s;
              if (!any) return Bad(field, "no wall is servo-controlled in this stage");
            } else if constexpr (std::is_same_v<T, KineticEnergyEnd>) {
              SEEP_RETURN_IF_ERROR(Requires(field, HasMechanics(scene_), "contacts"));
              if (!(std::isfinite(c.ratio) && c.ratio > 0.0 && c.ratio < 1.0)) {
                return Bad(field, fmt::format("must lie in (0, 1) (got {})", c.ratio));
              }
            } else if constexpr (std::is_same_v<T, BondsBrokenEnd>) {
              SEEP_RETURN_IF_ERROR(Requires(field, HasEffect<BondsEffectSpec>(scene_), "bonds"));
              if (c.count == 0) return Bad(field, "must be >= 1");
            } else if constexpr (std::is_same_v<T, BreakthroughEnd>) {
              SEEP_RETURN_IF_ERROR(
                  Requires(field, HasEffect<RedetectionEffectSpec>(scene_), "redetection"));
              if (!scene_.boundary.radial) {
                return Bad(field, "needs a radial boundary (a well to break through from)");
              }
            } else if constexpr (std::is_same_v<T, WellPressurePastPeakEnd>) {
              SEEP_RETURN_IF_ERROR(
                  Requires(field, HasEffect<InjectionEffectSpec>(scene_), "injection"));
              if (!(std::isfinite(c.fraction) && c.fraction > 0.0 && c.fraction < 1.0)) {
                return Bad(field, fmt::format("must lie in (0, 1) (got {})", c.fraction));
              }
            }
            return Status::Ok();
          },
          stage.end[k]);
      if (!checked.ok()) return checked;
    }
    if (!InRange(stage.max_duration_s, Range::kNonNegative)) {
      return Bad(at + ".max_duration_s",
                 fmt::format("must be a finite number >= 0 (got {})", stage.max_duration_s));
    }
    if (stage.max_duration_s > 0.0) bounded = true;
    if (!bounded) {
      return Bad(at + ".max_duration_s",
                 "must be > 0 when no duration_s or steps condition bounds the stage (a stage "
                 "whose conditions never hold would run forever)");
    }
    if (stage.continue_at_max_duration && !(stage.max_duration_s > 0.0)) {
      return Bad(at + ".continue_at_max_duration", "needs max_duration_s > 0");
    }
    return Status::Ok();
  }

  const SceneSpec& scene_;
  const WallsEffectSpec* walls_;
  std::vector<bool> servo_;  // per wall of the walls effect: servo-controlled now
};

}  // namespace

Status ValidateStages(const SceneSpec& scene) {
  if (scene.stages.empty()) return Status::Ok();
  const bool steps =
      HasMechanics(scene) || (HasFlow(scene) && scene.solver.kind != SolverKind::kSteady);
  if (!steps) {
    return InvalidArgument(
        "scene.stages: a steady scene has no time to divide into stages (use a transient solver "
        "or moving particles)");
  }
  if (scene.solver.end_time_s != 0.0) {
    return InvalidArgument(fmt::format(
        "scene.solver.end_time_s: must be 0 (unset) in a scene with stages: each stage ends on "
        "its own end conditions (got {})",
        scene.solver.end_time_s));
  }
  StageValidator validator(scene);
  for (std::size_t i = 0; i < scene.stages.size(); ++i) {
    SEEP_RETURN_IF_ERROR(validator.Validate(i, scene.stages[i]));
  }
  return Status::Ok();
}

}  // namespace seep::core
