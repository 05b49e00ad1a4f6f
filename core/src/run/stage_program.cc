#include "seep/core/run/stage_program.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <type_traits>

namespace seep::core {
namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();

// A stage-time bound counts as reached within a millionth of a step: the same comparison decides
// before the step (BoundReached) and after it (AfterStep), on the same numbers.
bool Reached(double stage_time, double bound, double dt) { return stage_time >= bound - 1e-6 * dt; }

// Applies a stage's settings at stage time t onto `c` (t = infinity: the values it ends on).
void ApplyStage(const StageSpec& stage, double t, StageControls* c) {
  const auto set = [t](const std::optional<SettingSpec>& setting, double* value) {
    if (setting) *value = SettingAt(*setting, t);
  };
  set(stage.injection_rate_m2_s, &c->injection_rate_m2_s);
  if (stage.local_damping_alpha) c->local_damping_alpha = *stage.local_damping_alpha;
  set(stage.inlet_pressure_pa, &c->inlet_pressure_pa);
  set(stage.outlet_pressure_pa, &c->outlet_pressure_pa);
  set(stage.well_pressure_pa, &c->well_pressure_pa);
  set(stage.outer_pressure_pa, &c->outer_pressure_pa);
  for (const StageWallSpec& w : stage.walls) {
    StageControls::Wall& wall = c->walls[w.wall];
    if (w.servo_stress_pa) {
      wall.servo_stress_pa = SettingAt(*w.servo_stress_pa, t);
      wall.normal_velocity_m_s.reset();
    } else if (w.normal_velocity_m_s) {
      wall.servo_stress_pa = 0.0;
      wall.normal_velocity_m_s = SettingAt(*w.normal_velocity_m_s, t);
    } else if (w.fixed) {
      wall.servo_stress_pa = 0.0;
      wall.normal_velocity_m_s.reset();
    }
    if (w.drain_pressure_pa) wall.drain_pressure_pa = SettingAt(*w.drain_pressure_pa, t);
  }
  for (const StageRegionSpec& r : stage.regions) set(r.value, &c->regions[r.region]);
}

template <typename T>
const T* FindCondition(const StageSpec& stage) {
  for (const EndConditionSpec& c : stage.end) {
    if (const T* t = std::get_if<T>(&c)) return t;
  }
  return nullptr;
}

// Every servo wall's controlled stress (total, or effective where the wall asks for it) within
// `tolerance` x its target.
bool ServosHold(const LiveState& s, double tolerance) {
  const auto* walls = FindEffect<WallsEffectSpec>(*s.scene);
  if (walls == nullptr) return false;
  bool any = false;
  for (std::size_t w = 0; w < walls->walls.size(); ++w) {
    const WallSpec& wall = walls->walls[w];
    if (!(wall.servo_stress_pa > 0.0)) continue;
    if (w >= s.wall_stress_pa.size()) return false;
    const double measured = s.ServoStressPa(w, wall.servo_effective_stress);
    if (!(std::abs(measured - wall.servo_stress_pa) <= tolerance * wall.servo_stress_pa)) {
      return false;
    }
    any = true;
  }
  return any;
}

}  // namespace

StageControls ControlsOf(const SceneSpec& scene) {
  StageControls c;
  if (const auto* injection = FindEffect<InjectionEffectSpec>(scene)) {
    c.injection_rate_m2_s = injection->rate_m2_s;
  }
  if (const auto* damping = FindEffect<LocalDampingEffectSpec>(scene)) {
    c.local_damping_alpha = damping->alpha;
  }
  c.inlet_pressure_pa = scene.boundary.inlet_pressure_pa;
  c.outlet_pressure_pa = scene.boundary.outlet_pressure_pa;
  if (const auto& radial = scene.boundary.radial) {
    c.well_pressure_pa = radial->well_pressure_pa;
    c.outer_pressure_pa = radial->outer_pressure_pa;
  }
  if (const auto* walls = FindEffect<WallsEffectSpec>(scene)) {
    for (const WallSpec& w : walls->walls) {
      StageControls::Wall wall;
      wall.servo_stress_pa = w.servo_stress_pa;
      wall.normal_velocity_m_s = w.normal_velocity_m_s;
      if (w.drain) wall.drain_pressure_pa = w.drain->pressure_pa;
      c.walls.push_back(wall);
    }
  }
  for (const BoundaryRegionSpec& region : scene.boundary.regions) {
    c.regions.push_back(ConditionValue(region.condition));
  }
  return c;
}

void WriteControls(const StageControls& c, SceneSpec* scene) {
  for (EffectSpec& effect : scene->effects) {
    if (auto* injection = std::get_if<InjectionEffectSpec>(&effect)) {
      injection->rate_m2_s = c.injection_rate_m2_s;
    } else if (auto* damping = std::get_if<LocalDampingEffectSpec>(&effect)) {
      damping->alpha = c.local_damping_alpha;
    } else if (auto* walls = std::get_if<WallsEffectSpec>(&effect)) {
      for (std::size_t w = 0; w < walls->walls.size() && w < c.walls.size(); ++w) {
        WallSpec& wall = walls->walls[w];
        wall.servo_stress_pa = c.walls[w].servo_stress_pa;
        wall.normal_velocity_m_s = c.walls[w].normal_velocity_m_s;
        if (wall.drain && c.walls[w].drain_pressure_pa) {
          wall.drain->pressure_pa = *c.walls[w].drain_pressure_pa;
        }
      }
    }
  }
  scene->boundary.inlet_pressure_pa = c.inlet_pressure_pa;
  scene->boundary.outlet_pressure_pa = c.outlet_pressure_pa;
  if (auto& radial = scene->boundary.radial) {
    radial->well_pressure_pa = c.well_pressure_pa;
    radial->outer_pressure_pa = c.outer_pressure_pa;
  }
  auto& regions = scene->boundary.regions;
  for (std::size_t k = 0; k < regions.size() && k < c.regions.size(); ++k) {
    SetConditionValue(c.regions[k], &regions[k].condition);
  }
}

StageProgram::StageProgram(const SceneSpec& scene)
    : stages_(scene.stages), initial_(ControlsOf(scene)), base_(initial_) {}

std::string StageProgram::Name(std::uint32_t index) const {
  if (index < stages_.size() && !stages_[index].name.empty()) return stages_[index].name;
  return fmt::format("stage{}", index + 1);
}

StageControls StageProgram::ControlsBefore(std::uint32_t index) const {
  StageControls c = initial_;
  for (std::uint32_t k = 0; k < index && k < stages_.size(); ++k) {
    ApplyStage(stages_[k], kInfinity, &c);
  }
  return c;
}

StageControls StageProgram::ControlsAt(double stage_time_s) const {
  StageControls c = base_;
  if (!done()) ApplyStage(stages_[state_.index], stage_time_s, &c);
  return c;
}

double StageProgram::TimeBound() const {
  if (done()) return kInfinity;
  const StageSpec& stage = stages_[state_.index];
  double bound = stage.max_duration_s > 0.0 ? stage.max_duration_s : kInfinity;
  for (const EndConditionSpec& c : stage.end) {
    if (const auto* d = std::get_if<DurationEnd>(&c)) bound = std::min(bound, d->duration_s);
  }
  return bound;
}

bool StageProgram::BoundReached(std::uint64_t step, double time_s, double dt) const {
  if (done()) return false;
  if (Reached(time_s - state_.start_time_s, TimeBound(), dt)) return true;
  const auto* steps = FindCondition<StepsEnd>(stages_[state_.index]);
  return steps != nullptr && step - state_.start_step >= steps->steps;
}

std::uint64_t StageProgram::EstimateSteps(double dt) const {
  double steps = 0.0;
  for (std::uint32_t k = state_.index; k < stages_.size(); ++k) {
    const StageSpec& stage = stages_[k];
    double bound = stage.max_duration_s > 0.0 ? stage.max_duration_s / dt : kInfinity;
    for (const EndConditionSpec& c : stage.end) {
      if (const auto* d = std::get_if<DurationEnd>(&c)) bound = std::min(bound, d->duration_s / dt);
      if (const auto* n = std::get_if<StepsEnd>(&c)) {
        bound = std::min(bound, static_cast<double>(n->steps));
      }
    }
    steps += std::ceil(bound);
  }
  return static_cast<std::uint64_t>(std::min(steps, 1e18));
}

double StageProgram::FractionDone(std::uint64_t step, double time_s) const {
  if (!active()) return 0.0;
  if (done()) return 1.0;
  const StageSpec& stage = stages_[state_.index];
  double share = 0.0;
  if (const double bound = TimeBound(); std::isfinite(bound)) {
    share = (time_s - state_.start_time_s) / bound;
  }
  if (const auto* steps = FindCondition<StepsEnd>(stage)) {
    share = std::max(
        share, static_cast<double>(step - state_.start_step) / static_cast<double>(steps->steps));
  }
  share = std::clamp(share, 0.0, 0.99);
  return (state_.index + share) / static_cast<double>(stages_.size());
}

StageOutcome StageProgram::AfterStep(const LiveState& s, const StepInfo& info, bool may_end) {
  StageOutcome out;
  if (done()) return out;
  const StageSpec& stage = stages_[state_.index];
  const double tau = info.time_s - state_.start_time_s;
  // Track what the conditions watch, every step (a condition may only end the stage at a flow
  // update, but its history counts from every step).
  if (s.moves()) state_.bonds_broken += s.contacts->broken_bonds().size();
  double kinetic = 0.0;
  if (FindCondition<KineticEnergyEnd>(stage) != nullptr) {
    kinetic = KineticEnergy(s.particles);
    state_.peak_kinetic_energy_j = std::max(state_.peak_kinetic_energy_j, kinetic);
  }
  std::optional<double> well;
  if (FindCondition<WellPressurePastPeakEnd>(stage) != nullptr && info.flow_update) {
    well = WellPressure(s.net);
    if (well && (!state_.peak_well_pressure_pa || *well > *state_.peak_well_pressure_pa)) {
      state_.peak_well_pressure_pa = *well;
    }
  }
  if (const auto* held = FindCondition<ServoHeldEnd>(stage)) {
    if (!ServosHold(s, held->tolerance_fraction)) {
      state_.held_since_s = -1.0;
    } else if (state_.held_since_s < 0.0) {
      state_.held_since_s = tau;
    }
  }
  for (std::size_t k = 0; k < stage.end.size(); ++k) {
    const bool holds = std::visit(
        [&](const auto& c) -> bool {
          using T = std::decay_t<decltype(c)>;
          if constexpr (std::is_same_v<T, DurationEnd>) {
            return Reached(tau, c.duration_s, info.dt);
          } else if constexpr (std::is_same_v<T, StepsEnd>) {
            return info.step - state_.start_step >= c.steps;
          } else if constexpr (std::is_same_v<T, ServoHeldEnd>) {
            return may_end && state_.held_since_s >= 0.0 &&
                   Reached(tau - state_.held_since_s, c.hold_s, info.dt);
          } else if constexpr (std::is_same_v<T, KineticEnergyEnd>) {
            return may_end && state_.peak_kinetic_energy_j > 0.0 &&
                   kinetic <= c.ratio * state_.peak_kinetic_energy_j;
          } else if constexpr (std::is_same_v<T, BondsBrokenEnd>) {
            return may_end && state_.bonds_broken >= c.count;
          } else if constexpr (std::is_same_v<T, BreakthroughEnd>) {
            return may_end && (s.net.well_domain < 0 || s.net.well_on_wall);
          } else if constexpr (std::is_same_v<T, WellPressurePastPeakEnd>) {
            const std::optional<double>& peak = state_.peak_well_pressure_pa;
            return may_end && well && peak && *peak > 0.0 && *well <= (1.0 - c.fraction) * *peak;
          }
        },
        stage.end[k]);
    if (holds) {
      out.kind = StageOutcome::Kind::kEnded;
      out.ended_by = static_cast<int>(k);
      return out;
    }
  }
  if (stage.max_duration_s > 0.0 && Reached(tau, stage.max_duration_s, info.dt)) {
    if (stage.continue_at_max_duration) {
      out.kind = StageOutcome::Kind::kEnded;
      return out;
    }
    std::string conditions;
    for (const EndConditionSpec& c : stage.end) {
      conditions += fmt::format("{}{}", conditions.empty() ? "" : ", ", EndConditionName(c));
    }
    out.kind = StageOutcome::Kind::kFailed;
    out.message = fmt::format(
        "stage {}/{} '{}' (scene.stages[{}]): reached max_duration_s = {} s at t = {} s (step {}) "
        "before any of its end conditions held ({}); raise max_duration_s, or set "
        "continue_at_max_duration to move on",
        state_.index + 1, stages_.size(), Name(state_.index), state_.index, stage.max_duration_s,
        info.time_s, info.step, conditions);
  }
  return out;
}

void StageProgram::Advance(const Metrics& at_end, int ended_by, std::uint64_t step, double time_s) {
  const std::uint32_t k = state_.index + 1;
  std::vector<std::pair<std::string, double>>& ended = state_.ended_metrics;
  for (const auto& [name, value] : at_end)
    ended.emplace_back(fmt::format("stage{}_{}", k, name), value);
  ended.emplace_back(fmt::format("stage{}_duration_s", k), time_s - state_.start_time_s);
  ended.emplace_back(fmt::format("stage{}_ended_by", k), static_cast<double>(ended_by));
  std::sort(ended.begin(), ended.end());
  state_.index = k;
  state_.start_step = step;
  state_.start_time_s = time_s;
  state_.bonds_broken = 0;
  state_.peak_kinetic_energy_j = 0.0;
  state_.peak_well_pressure_pa.reset();
  state_.held_since_s = -1.0;
  base_ = ControlsBefore(k);
}

void StageProgram::AddMetrics(Metrics* out) const {
  if (!active()) return;
  for (const auto& [name, value] : state_.ended_metrics) (*out)[name] = value;
  (*out)["stages_ended"] = static_cast<double>(state_.index);
}

Status StageProgram::Restore(const StageRunState& saved, std::uint64_t step, double time_s) {
  if (saved.index > stages_.size()) {
    return DataLoss(fmt::format("snapshot.stages.index: {} is past this scene's {} stages",
                                saved.index, stages_.size()));
  }
  if (saved.start_step > step || !(std::isfinite(saved.start_time_s) && saved.start_time_s >= 0.0 &&
                                   saved.start_time_s <= time_s)) {
    return DataLoss(fmt::format(
        "snapshot.stages.start_step/start_time_s: ({}, {} s) is not a point before step {} "
        "(t = {} s)",
        saved.start_step, saved.start_time_s, step, time_s));
  }
  for (const auto& [field, value] :
       {std::pair{"peak_kinetic_energy_j", saved.peak_kinetic_energy_j},
        std::pair{"held_since_s", saved.held_since_s},
        std::pair{"peak_well_pressure_pa", saved.peak_well_pressure_pa.value_or(0.0)}}) {
    if (!std::isfinite(value)) {
      return DataLoss(fmt::format("snapshot.stages.{}: not finite", field));
    }
  }
  for (const auto& [name, value] : saved.ended_metrics) {
    if (!std::isfinite(value) || name.rfind("stage", 0) != 0) {
      return DataLoss(
          fmt::format("snapshot.stages.ended_metrics['{}']: not a finite stage metric", name));
    }
  }
  state_ = saved;
  base_ = ControlsBefore(state_.index);
  return Status::Ok();
}

}  // namespace seep::core
