// CoupledStepper: the step loop of a scene whose particles move (design-anchors §5.4). It owns the
// live state and the effects the scene lists, with one list per hook built once at set-up.
//
// One step (velocity-Verlet, the DEM step dt):
//   IntegrateFirstHalf; MoveWalls
//   kForce effects      contacts (set), gravity, fluid pressure forces
//   kPostForce effects  local damping, servo walls
//   IntegrateSecondHalf
//   kEndOfStep effects  on flow-update steps only: volume change, apertures, flow (sub-cycled or
//                       implicit over the flow interval), re-detection (+ remap)
// After an end-of-step effect replaced the network (re-detection), every effect re-binds to it.
//
// The flow interval is `flow_every` DEM steps (FlowEffectSpec::every_steps; automatic = as many
// DEM steps as fit in dt_factor x dt_crit of the initial network, at least 1, in which case the
// explicit solver sub-cycles inside the DEM step). The last step of a run closes the interval.
#pragma once

#include <spdlog/logger.h>

#include <memory>
#include <string_view>
#include <utility>
#include <vector>

#include "seep/core/effects/effect.h"
#include "seep/core/run/simulation_snapshot.h"

namespace seep::core {

class CoupledStepper {
 public:
  // `net` is the network built at set-up (for scenes with flow), else only its packing is used.
  static Result<std::unique_ptr<CoupledStepper>> Create(const SceneSpec& scene, SceneNetwork net,
                                                        bool has_network);

  // Takes step `step` (1-based) of a run of `total_steps`.
  Status Step(std::uint64_t step, std::uint64_t total_steps);

  double dt() const { return state_.dem_dt; }
  std::uint64_t flow_every() const { return flow_every_; }
  const CoupledState& state() const { return state_; }
  // For the Simulation's restore of the pressures (state, not coefficients).
  SceneNetwork& mutable_network() { return state_.net; }
  // Names of the effects in each hook list, in call order (for the log and the tests).
  std::vector<std::string_view> HookList(Hook hook) const;

  // Wall seconds spent in each effect's hooks (and in the integration, as "integration") since
  // set-up, in the canonical effect order: what each effect costs a run (the benchmarks and the
  // run report). Not state: never checkpointed, never read by the physics.
  std::vector<std::pair<std::string_view, double>> EffectSeconds() const;

  // V_p of every flow node as a report shows it: current, also where the step keeps the
  // detected V_p (apparent storage; see VolumeChangeEffect).
  std::vector<double> ReportedPoreVolumes() const;

  void SaveTo(MechanicsSnapshot* out) const;
  // Restores the state of a stepper of the same scene; DATA_LOSS naming what does not fit. The
  // flow pressures are restored by the caller afterwards (they are part of SimulationSnapshot).
  Status RestoreFrom(const MechanicsSnapshot& snap);

 private:
  explicit CoupledStepper(const SceneSpec& scene);
  Status RebindAll();
  // Forces of the initial state, so that the first half-kick has them (velocity-Verlet).
  Status InitialForces();
  Status CheckParticlesFinite(std::uint64_t step) const;

  SceneSpec scene_;
  CoupledState state_;
  std::vector<std::unique_ptr<Effect>> effects_;
  // Hook lists hold indices into effects_ (so each call can be timed against its effect).
  std::vector<std::size_t> force_, post_force_, end_of_step_;
  std::vector<double> effect_seconds_;  // per effects_ entry
  double integration_seconds_ = 0.0;
  const Effect* flow_effect_ = nullptr;
  std::uint64_t flow_every_ = 1;
};

}  // namespace seep::core
