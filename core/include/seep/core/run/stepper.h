// Stepper: the one step loop of every scene (docs/architecture.md §4, after LAMMPS's Verlet with
// its fix masks). It owns the live state and the effects the scene lists, with one list per hook
// built once at set-up; a frozen packing is a stepper whose only effect is flow (no integration), a
// steady scene is that flow in steady mode for one step.
//
// One step (Step()):
//   moving particles: IntegrateFirstHalf; MoveWalls
//   kFlowUpdate effects on flow-update steps only: volume change, flow (so that the forces act with
//                       the pressure of the positions they act at: effect.h says why)
//   kForce effects      contacts (set), gravity, fluid pressure forces
//   kPostForce effects  local damping, servo walls
//   moving particles: IntegrateSecondHalf
//   kEndOfStep effects  on flow-update steps only: apertures, re-detection (+ remap), injection
// and, with moving particles, the energy guard's books (energy_guard.h): the fluid forces' work
// around their effect, the walls' after the forces, its check every EnergyGuard::kCheckEvery steps
// and at the end.
// After an end-of-step effect replaced the network (re-detection), every effect re-binds to it.
//
// The clock (determinism across a resume rests on it: the step count and the step come from the
// scene only, samples fire at fixed step numbers, never on wall time):
//   frozen transient  dt = dt_factor x dt_crit of the network; time adds up the steps and the last
//                     step is the time left, so it lands on end_time_s exactly;
//   moving            dt = the DEM step (contacts' stable estimate, combined with the fluid's
//                     stiffness when pressure follows deformation); time = step x dt; a flow
//                     update every `flow_every` steps (FlowEffectSpec::every_steps) and at the end.
//                     A re-detection that makes the pore fluid stiffer (new small domains)
//                     shortens dt to what the new network allows, from that step on (time and
//                     intervals then count from it; the step is never lengthened again); the
//                     checkpoint carries the clock;
//   steady            one step, no time.
//
// The time series stays bounded whatever the progress interval: a row is kept every
// `series_stride()` steps, which starts at the progress interval; when a new row would make more
// than kMaxSeriesRows, every other row is dropped and the stride doubles. The stride is a function
// of the step alone (SeriesStrideAt), so a resumed run keeps the very rows of an uninterrupted one.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include "seep/core/effects/effect_set.h"
#include "seep/core/effects/live_state.h"
#include "seep/core/run/energy_guard.h"
#include "seep/core/run/reversal_guard.h"
#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/run/stage_program.h"

namespace seep::core {

class Stepper {
 public:
  // Most rows the time series holds (even, so that a halving keeps the newest row).
  static constexpr std::size_t kMaxSeriesRows = 1024;

  // `net` is the network built at set-up (for scenes with flow), else only its packing is used.
  static Result<std::unique_ptr<Stepper>> Create(const SceneSpec& scene, SceneNetwork net,
                                                 bool has_network);

  // Takes the next step.
  Status Step();

  // A scene with stages finishes when its last stage ends; another at its last step.
  bool finished() const { return program_.active() ? program_.done() : step_ >= total_steps_; }
  // 0..1 (with stages: the stages ended plus the current one's share of its bound).
  double FractionDone() const;
  std::uint64_t step() const { return step_; }
  double time_s() const { return time_s_; }
  // The last step; with stages an estimate (the stages' bounds), since conditions end them.
  std::uint64_t total_steps() const { return total_steps_; }
  // The scene's stages and where the run stands in them (inactive without stages).
  const StageProgram& stages() const { return program_; }
  std::uint64_t sample_every() const { return sample_every_; }
  double dt() const { return dt_; }  // 0 for a steady scene
  std::uint64_t flow_every() const { return flow_every_; }
  // The scene as it stands now: with stages, the current stage's settings written in.
  const SceneSpec& scene() const { return scene_; }
  const LiveState& state() const { return state_; }
  const TimeSeries& series() const { return series_; }
  // Steps between two rows of series() now (a multiple of sample_every()).
  std::uint64_t series_stride() const { return series_stride_; }
  // The newest sample (one value per series column), taken every sample_every() steps whether
  // or not series() keeps it: what live progress shows.
  const std::vector<double>& latest_sample() const { return latest_sample_; }
  // The energy guard's headroom now: K / (E_0 + W), which it fails above
  // EnergyGuard::kAllowedRatio (0 where it does not apply).
  double EnergyRatio() const { return guard_.Ratio(state_); }
  // One line for the log: the step, the step count, the flow interval and the hook lists.
  std::string Describe() const;

  // Names of the effects in each hook list, in call order (for the log and the tests).
  std::vector<std::string_view> HookList(Hook hook) const;
  // Wall seconds spent in each effect's hooks (and in the integration, as "integration") since
  // set-up, in the canonical effect order: what each effect costs a run (the benchmarks and the
  // run report). Not state: never checkpointed, never read by the physics.
  std::vector<std::pair<std::string_view, double>> EffectSeconds() const;

  // V_p of every flow node as a report shows it: current, also where the step keeps the detected
  // V_p (apparent storage; see VolumeChangeEffect).
  std::vector<double> ReportedPoreVolumes() const;
  // The measurements of the current state, every effect's included.
  Metrics Measure() const;

  SimulationSnapshot TakeSnapshot() const;
  // Continues from a snapshot of a stepper of the same scene; DATA_LOSS naming what does not fit,
  // and then the state is unchanged.
  Status Restore(const SimulationSnapshot& snap);

 private:
  explicit Stepper(const SceneSpec& scene);
  Status SetClock();
  Status RebindAll();
  // With stages: writes the current stage's settings at stage time t into the live scene and has
  // the effects take them up, if they differ from the last applied (or `force`).
  Status ApplyStageControls(double stage_time_s, bool force);
  Status ReconfigureAll();
  // The current stage ended after this step (by end condition `ended_by`, -1: max duration):
  // records its metrics and starts the next; the clock's intervals restart from here.
  void EndStage(int ended_by);
  // The effects' and the clock's measurements, without the ended stages' metrics.
  Metrics MeasureRun() const;
  // Pressure follows deformation and pushes the particles: the fluid is a spring the DEM step
  // must resolve.
  bool FluidIsASpring() const;
  // After a re-detection: the step the new network allows, if shorter than the current one.
  void ShortenStepForTheFluid(const StepInfo& info);
  // The last step of the run on a snapshot's clock (DATA_LOSS when that clock cannot be this
  // scene's at `step`).
  Result<std::uint64_t> ClockTotalSteps(const MechanicsSnapshot& clock, std::uint64_t step) const;
  // Forces of the initial state, so that the first half-kick has them (velocity-Verlet).
  Status InitialForces();
  // Force effect k's AddForces; around the fluid forces' (moving scenes) the energy guard takes
  // their work over a step of guard_dt.
  Status AddForcesOf(std::size_t k, const StepInfo& info, double guard_dt);
  Status CheckParticlesFinite(std::uint64_t step) const;
  StepInfo NextStep() const;
  void Sample();
  // The series stride at `step`: sample_every() doubled for every halving that an uninterrupted
  // run makes up to that step.
  std::uint64_t SeriesStrideAt(std::uint64_t step) const;
  // Drops every other row (the odd ones: row k was sampled at step k x stride) and doubles the
  // stride.
  void HalveSeries();
  void SaveMechanics(MechanicsSnapshot* out) const;
  Status RestoreMechanics(const MechanicsSnapshot& snap, const std::vector<double>& pressure);

  SceneSpec scene_;  // live: a stage's settings are written into it
  LiveState state_;
  StageProgram program_;
  StageControls applied_;            // the stage settings last written into scene_
  std::uint32_t applied_stage_ = 0;  // the stage they were written for
  std::uint32_t step_stage_ = 0;     // the stage the last step belonged to (the series' column)
  EffectSet effects_;
  // Hook lists hold indices into effects_.all (so each call can be timed against its effect).
  std::vector<std::size_t> flow_update_, force_, post_force_, end_of_step_;
  std::vector<double> effect_seconds_;       // per effects_.all entry
  std::vector<const Effect*> sample_order_;  // whose series columns come in which order
  double integration_seconds_ = 0.0;
  // The clock.
  double dt_ = 0.0;
  double contact_dt_ = 0.0;        // the contacts' stable step (moving)
  double fluid_limited_dt_ = 0.0;  // the step the fluid's stiffness allows (moving), else inf
  std::uint64_t clock_step_ = 0;   // the step and time the current dt began at (moving)
  double clock_time_s_ = 0.0;
  std::uint64_t total_steps_ = 1;
  std::uint64_t sample_every_ = 1;
  std::uint64_t flow_every_ = 1;
  std::uint64_t step_ = 0;
  double time_s_ = 0.0;
  std::uint64_t series_stride_ = 1;
  TimeSeries series_;
  std::vector<double> latest_sample_;
  EnergyGuard guard_;        // moving scenes: fails an unstable step on energy
  ReversalGuard reversals_;  // and on motion that reverses every step
};

// OK when every metric is a finite number; else FAILED_PRECONDITION naming the first one that is
// not (a report is refused where it is measured, not where it is stored).
Status CheckMetricsFinite(const Metrics& metrics);

}  // namespace seep::core
