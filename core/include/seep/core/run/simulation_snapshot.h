// SimulationSnapshot: everything a Simulation needs to continue bit-identically on the same
// build, as plain arrays (docs/architecture.md §3). What is rebuilt deterministically from
// the scene (the packing of a rigid scene, its contacts, domains and pipes, the solver's caches)
// is not stored; the scene's hash in the checkpoint header ties the two together.
//
// The service stores it as seep.v1.SimulationState (service/codec/simulation_state_codec).
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "seep/core/dem/dem_contact_state.h"
#include "seep/core/effects/effect_state.h"
#include "seep/core/effects/fluid_ledger.h"

namespace seep::core {

// A table of samples taken at fixed step numbers, so that a resumed run samples at the same
// steps as an uninterrupted one. Row-major: values[row * columns.size() + column].
struct TimeSeries {
  std::vector<std::string> columns;  // the first column is always "time_s"
  std::vector<double> values;

  std::size_t rows() const { return columns.empty() ? 0 : values.size() / columns.size(); }
};

// The energy guard's account (run/energy_guard.h), J per m of thickness: what the disks held at
// the start, gravity's moment sum m_i g.x_i then, and the work of walls and held particles and of
// the pore fluid since; and the last step's forces that the next step's work averages with.
struct EnergyGuardState {
  double initial_j = 0.0;
  double gravity_moment_j = 0.0;
  double work_j = 0.0;
  double fluid_work_j = 0.0;
  // The forces of the last step, which each step's work averages with its own (the trapezoid rule
  // is exact for a spring; the step's end force alone loses k dx^2 / 2 a step): per wall its
  // contacts' load, per held particle its contacts' force (x, y), per particle the pore fluid's
  // force (x, y; empty without fluid forces).
  std::vector<double> wall_load, held_fx, held_fy, fluid_fx, fluid_fy;
};

// The reversal guard's memory (run/reversal_guard.h): the checks in a row at which the disks'
// reversal ratio passed its limit, and per wall the speed it moved with last step and the steps in
// a row its servo reversed it.
struct ReversalGuardState {
  std::uint32_t disk_checks = 0;
  std::vector<double> wall_speed;
  std::vector<std::uint32_t> wall_reversals;
};

// The state of a scene whose particles move (the contacts effect): the live state the stepper owns
// (particles, walls and contact history, the topology of the current network — rebuilt on restore
// by the same detection from the positions and contacts it was detected from — and the flow
// coefficients that moved since: volumes, apertures), and each effect's own part.
struct MechanicsSnapshot {
  // Particles: the dynamic fields (mass, radius and inertia come from the scene).
  std::vector<double> x, y, vx, vy, omega, fx, fy, torque;
  // Walls: point, normal, velocity, six values per wall.
  std::vector<double> walls;
  DemContactState contacts;
  // The network's detection: positions and contact pairs it was detected from.
  std::vector<double> detection_x, detection_y;
  std::vector<std::int32_t> detection_i, detection_j;
  std::vector<double> detection_gap;
  // With walls in the fluid: the wall lines it was detected with (px, py, nx, ny per wall) and
  // the particle-wall contacts (particle, wall, gap) it used.
  std::vector<double> detection_walls;
  std::vector<std::int32_t> detection_wall_particle, detection_wall_wall;
  std::vector<double> detection_wall_gap;
  // Flow coefficients per node / pipe of that network.
  std::vector<double> apparent_volume, pore_volume, aperture;
  // Head offsets of the pipes (fluid weight only, else empty): measured from the centroids of
  // the last flow update, which the positions of a later step no longer give.
  std::vector<double> pipe_head_offset;
  std::uint64_t topology_version = 0;
  // The clock (Stepper): the DEM step, the step and time it began at (a re-detection that
  // stiffens the pore fluid shortens it), the step the fluid allows and the flow interval.
  // dt = 0: a checkpoint written before the clock was kept, which runs on the scene's clock.
  double dt = 0.0;
  std::uint64_t clock_step = 0;
  double clock_time_s = 0.0;
  double fluid_limited_dt = 0.0;
  std::uint64_t flow_every = 0;
  // Each effect's run totals (its SaveTo / RestoreFrom).
  EffectStates effects;
  // Unset in checkpoints written before the guard kept it (it then starts from the restore).
  std::optional<EnergyGuardState> energy_guard;
  std::optional<ReversalGuardState> reversal_guard;
};

// Where a staged run stands (scene.stages, run/stage_program.h): the current stage, where it
// began, what its end conditions have tracked so far, and the metrics of the stages that ended.
struct StageRunState {
  std::uint32_t index = 0;       // the current stage, 0-based (the stage count once all have ended)
  std::uint64_t start_step = 0;  // the step and time the current stage began at
  double start_time_s = 0.0;
  std::uint64_t bonds_broken = 0;      // bonds broken since it began
  double peak_kinetic_energy_j = 0.0;  // the largest kinetic energy since it began, J per m
  std::optional<double> peak_well_pressure_pa;  // the well's peak since it began (unset: none yet)
  double held_since_s = -1.0;  // stage time since which every servo wall holds its target; -1: not
  // The metrics of the ended stages, "stage<k>_<metric>" (k from 1), sorted by name.
  std::vector<std::pair<std::string, double>> ended_metrics;
};

struct SimulationSnapshot {
  std::uint64_t step = 0;        // steps completed
  double time_s = 0.0;           // simulated time reached
  std::vector<double> pressure;  // per flow-network node (domains then reservoirs), Pa
  // The fluid books: the relative error of the last flow update (a sample between two updates
  // shows it) and the largest so far.
  double step_mass_balance_error = 0.0;
  double worst_mass_balance_error = 0.0;
  // The cumulative books; unset in a checkpoint written before the books existed.
  std::optional<FluidLedger> ledger;
  TimeSeries series;
  std::optional<MechanicsSnapshot> mechanics;  // scenes with the contacts effect only
  std::optional<StageRunState> stages;         // scenes with stages only
};

}  // namespace seep::core
