// Simulation: one scene as a live, steppable, snapshottable run (docs/architecture.md §3, after
// OpenMM's Context): spec -> stepper -> snapshot/report, and nothing else. Create() validates the
// scene, builds its packing, contacts, domains and pipes and the Stepper (the one step loop, with
// the effects the scene lists); Run() advances to the end time (or does the one steady solve) and
// can be stopped at any step boundary; TakeSnapshot()/Restore() carry the state across a process
// restart so that a resumed run ends bit-identical to an uninterrupted one on the same build
// (stepper.h says what the clock guarantees for that).
#pragma once

#include <spdlog/logger.h>

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <stop_token>
#include <string>
#include <utility>
#include <vector>

#include "seep/core/coupling/particle_view.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/run/stepper.h"
#include "seep/core/spec/scene_spec.h"
#include "seep/core/status.h"

namespace seep::core {

class Simulation;

struct RunProgress {
  std::uint64_t step = 0;
  double time_s = 0.0;         // simulated time
  double fraction_done = 0.0;  // 0..1
  // A scene with stages: the current stage, from 1 (0: the scene has none), of stage_count.
  std::uint32_t stage_index = 0;
  std::uint32_t stage_count = 0;
  std::string stage_name;
};

struct RunControl {
  // Called from the running thread at the scene's progress interval; must not block for long.
  std::function<void(const RunProgress&)> on_progress;
  // Called after every completed step with the simulation at a consistent step boundary: the
  // place to take a snapshot (the job service writes its periodic checkpoints from here).
  std::function<void(const Simulation&)> at_step_end;
  // A stop request ends the run at the next step boundary with a kCancelled status.
  std::stop_token stop;
  // Where the run logs (the service passes a logger named after the job); null = core::Logger().
  std::shared_ptr<spdlog::logger> logger;
};

struct RunReport {
  // Named measurements, sorted by name. Linear boundary: inflow/outflow_m2_per_s,
  // permeability_m2 (k = mu Q L / (H dP) with sample_length_m and sample_width_m, see
  // scene_network.h), and for lattices lattice_permeability_m2 and permeability_relative_error.
  // Radial boundary: well_flow_rate_m2_per_s (out of the well into the sample, > 0 when
  // p_w > p_e), outer_flow_rate_m2_per_s (into the outer reservoir), outer_reservoir_radius_m,
  // well_area_m2. Transient: dt_s, dt_crit_s, dt_over_dt_crit, limiting_domain,
  // mass_balance_error_max. Always: counts, porosity_2d, min/max_pressure_pa, steps,
  // simulated_time_s.
  std::vector<std::pair<std::string, double>> metrics;
  std::uint64_t steps = 0;
  double time_s = 0.0;
  // Boundary rates, pressure range and step mass-balance error over time (see Simulation).
  TimeSeries series;
};

class Simulation {
 public:
  static Result<Simulation> Create(const SceneSpec& scene,
                                   std::shared_ptr<spdlog::logger> logger = nullptr);

  // Continues from a snapshot taken from a simulation of the same scene. The snapshot's shape is
  // checked against this scene's network (DATA_LOSS naming what does not match); on error the
  // simulation is unchanged.
  Status Restore(const SimulationSnapshot& snapshot) { return stepper_->Restore(snapshot); }
  SimulationSnapshot TakeSnapshot() const { return stepper_->TakeSnapshot(); }

  // Advances until finished() or a stop request (kCancelled, the state stays at a step boundary
  // and can be snapshotted or run further). A numerical failure (non-finite pressure) is
  // FAILED_PRECONDITION with what to change, and so is a finished run whose report holds a
  // metric that is not a finite number (naming it).
  Status Run(const RunControl& control);

  bool finished() const { return stepper_->finished(); }
  std::uint64_t step() const { return stepper_->step(); }
  double time_s() const { return stepper_->time_s(); }
  // The last step; with stages an estimate from their bounds (conditions may end them sooner).
  std::uint64_t total_steps() const { return stepper_->total_steps(); }
  // Where the run stands: step, time, fraction done and, with stages, the current stage.
  RunProgress Progress() const;
  double dt_s() const { return stepper_->dt(); }  // 0 for a steady scene
  const SceneSpec& scene() const { return stepper_->scene(); }
  // The current network (for moving scenes: of the last re-detection; its packing holds the
  // positions it was detected from, particles() the current ones).
  const SceneNetwork& network() const { return stepper_->state().net; }
  // The particle centres and radii now (moving scenes: the DEM's; else the packing's).
  ParticleView particles() const;
  // V_p of every flow node of network() at the particles now, as reports and exports show it.
  std::vector<double> PoreVolumes() const { return stepper_->ReportedPoreVolumes(); }
  // The step loop: live state, effects, hook lists, per-effect timings.
  const Stepper& stepper() const { return *stepper_; }
  // The samples kept so far, at most Stepper::kMaxSeriesRows rows (see stepper.h).
  const TimeSeries& series() const { return stepper_->series(); }
  // The newest sample, one value per series column (live progress shows it).
  const std::vector<double>& latest_sample() const { return stepper_->latest_sample(); }

  // The measurements of the current state (the final ones once Run() returned OK).
  RunReport Report() const;

 private:
  explicit Simulation(std::unique_ptr<Stepper> stepper) : stepper_(std::move(stepper)) {}

  std::unique_ptr<Stepper> stepper_;
};

}  // namespace seep::core
