// StageProgram: runs a scene's stages (spec/stage_spec.h) inside the one step loop.
//
// The stepper asks it, before each step, for the controls of the current stage at its stage time
// (the scene's settings with every earlier stage's end values and this stage's constants or
// schedules applied) and writes them into its live scene, from which the effects re-read them
// (Effect::Reconfigure) when they change; after each step the program tracks the end conditions
// and says whether the stage ended (then the stepper records its metrics and starts the next) or
// failed at its max duration.
//
// Determinism: the controls are a function of (stage, stage time) alone, and every tracked
// quantity is in StageRunState, which the snapshot carries; so a resumed run applies the same
// controls at the same steps and ends its stages at the same steps.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "seep/core/effects/effect.h"
#include "seep/core/effects/live_state.h"
#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {

// The settings stages control, as they stand at one moment.
struct StageControls {
  struct Wall {
    double servo_stress_pa = 0.0;  // > 0: servo-controlled
    std::optional<double> normal_velocity_m_s;
    std::optional<double> drain_pressure_pa;
    bool operator==(const Wall&) const = default;
  };
  double injection_rate_m2_s = 0.0;
  double local_damping_alpha = 0.0;
  double inlet_pressure_pa = 0.0;
  double outlet_pressure_pa = 0.0;
  double well_pressure_pa = 0.0;
  double outer_pressure_pa = 0.0;
  std::vector<Wall> walls;  // per wall of the walls effect
  // Per boundary region: its pressure_pa or rate_m2_s, whichever its condition is.
  std::vector<double> regions;
  bool operator==(const StageControls&) const = default;
};

// The controls as a scene states them.
StageControls ControlsOf(const SceneSpec& scene);
// Writes them into the scene's fields (its effects' specs and its boundary).
void WriteControls(const StageControls& controls, SceneSpec* scene);

// What a step did to the current stage.
struct StageOutcome {
  enum class Kind { kContinue, kEnded, kFailed };
  Kind kind = Kind::kContinue;
  int ended_by = -1;    // the end condition that held (index into StageSpec::end); -1: max duration
  std::string message;  // kFailed: why, naming the stage
};

class StageProgram {
 public:
  StageProgram() = default;  // a scene without stages
  explicit StageProgram(const SceneSpec& scene);

  bool active() const { return !stages_.empty(); }
  bool done() const { return active() && state_.index >= stages_.size(); }
  std::uint32_t count() const { return static_cast<std::uint32_t>(stages_.size()); }
  const StageRunState& state() const { return state_; }
  // The current stage's name ("stage<k>" when it has none), k from 1.
  std::string Name(std::uint32_t index) const;

  // The controls of the current stage at stage time t (the last stage's end values once done).
  StageControls ControlsAt(double stage_time_s) const;
  // Whether ControlsAt changes within the current stage (it follows a schedule).
  bool Scheduled() const { return !done() && HasSchedule(stages_[state_.index]); }

  // Whether step `step` at time `time_s` reaches a bound of the current stage that is known
  // before the step is taken: a duration_s or steps condition, or max_duration_s. The stepper
  // makes that step a flow update (and a frozen scene's step lands on the duration exactly).
  bool BoundReached(std::uint64_t step, double time_s, double dt) const;
  // The stage time the current stage ends at for sure (its smallest duration_s or
  // max_duration_s), or infinity.
  double TimeBound() const;
  // Rough number of steps the remaining stages take at step dt (for progress and the default
  // sampling interval only; conditions may end them much earlier).
  std::uint64_t EstimateSteps(double dt) const;
  // 0..1: the stages ended plus the current one's share of its bound.
  double FractionDone(std::uint64_t step, double time_s) const;

  // After step `info.step`: tracks the end conditions on the state and decides. `may_end`: the
  // step may end the stage by a condition (scenes with flow end stages at flow updates only).
  StageOutcome AfterStep(const LiveState& s, const StepInfo& info, bool may_end);
  // Ends the current stage at (step, time) with the metrics measured there (recorded as
  // "stage<k>_<name>" with the stage's duration, end step and the condition that ended it), and
  // starts the next one there.
  void Advance(const Metrics& at_end, int ended_by, std::uint64_t step, double time_s);
  // The metrics of the ended stages, and where the run stands.
  void AddMetrics(Metrics* out) const;

  // Continues from a snapshot's stage state (DATA_LOSS naming what cannot be this scene's).
  Status Restore(const StageRunState& saved, std::uint64_t step, double time_s);

 private:
  // The controls at the start of stage `index`: the scene's, then every earlier stage's end.
  StageControls ControlsBefore(std::uint32_t index) const;

  std::vector<StageSpec> stages_;
  StageControls initial_;  // the scene's own settings
  StageControls base_;     // at the current stage's start
  StageRunState state_;
};

}  // namespace seep::core
