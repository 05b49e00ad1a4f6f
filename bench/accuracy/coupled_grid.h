// The choices a coupled (DEM + flow) run leaves to its user, swept by the accuracy bench's coupled
// problems (issue 20): the fluid's bulk modulus (real water down to a PFC-style scaled one), the
// flow solver (explicit sub-cycled or implicit), the flow interval, the DEM step's safety factor
// and the particle count. The grid is one at a time around a base: every K_f with each solver,
// then each other choice varied alone at each K_f with the implicit solver, so that a row's error
// can be read against the one choice that differs.
#pragma once

#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "accuracy_run.h"
#include "seep/core/run/simulation.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::bench {

inline constexpr double kRealWaterBulkModulusPa = 2.2e9;

struct CoupledChoice {
  double bulk_modulus_pa = kRealWaterBulkModulusPa;
  core::SolverKind solver = core::SolverKind::kImplicit;
  std::uint32_t flow_every = 0;  // DEM steps per flow update; 0 = automatic
  double dt_safety = 0.5;        // contacts.dt_safety
  int size = 0;                  // the problem's size index (its particle counts)
};

struct CoupledGrid {
  std::vector<double> bulk_moduli;        // first: real water
  std::vector<std::uint32_t> flow_every;  // besides automatic (0)
  std::vector<double> dt_safety;          // the first is the base
  int sizes = 1;                          // size indices 0..sizes-1; 0 is the base
  // The solver of the base and of every one-at-a-time variation; with both_solvers every K_f
  // also runs with the other one.
  core::SolverKind base_solver = core::SolverKind::kImplicit;
  bool both_solvers = true;
};

// The grid's runs, base first: (K_f x solver), then flow_every, dt_safety and size varied alone
// at every K_f (base_solver).
std::vector<CoupledChoice> CoupledChoices(const CoupledGrid& grid);

// Writes the choice into a coupled scene: K_f, the solver (explicit at 0.9 dt_crit sub-cycled in
// the DEM step; implicit with the flow interval set by the DEM step), the flow effect's interval
// and the contacts' dt_safety.
void ApplyChoice(const CoupledChoice& choice, core::SceneSpec* scene);

struct CoupledRun {
  std::optional<core::Simulation> simulation;  // after Run()
  double wall_s = 0.0;                         // Simulation::Run
  double setup_s = 0.0;                        // Simulation::Create
  core::Status status;
};

// One run of `scene` (coupled runs last seconds: one repeat), `at_step_end` called after every
// step; the run ends early (status OK) once it returns true.
CoupledRun RunCoupled(const core::SceneSpec& scene,
                      const std::function<bool(const core::Simulation&)>& at_step_end);

// A row for the run: the choice, steps, domains, wall time, the fluid-to-skeleton stiffness the
// run reports (coupling_fluid_to_skeleton_stiffness), and `error` (NaN and the status in the note
// when the run failed).
AccuracyRun CoupledRow(const std::string& problem, const CoupledChoice& choice, int particles,
                       const CoupledRun& run, double error, const std::string& error_kind,
                       const std::string& note);

// The soft, frictionless lattice contacts of the undrained and consolidation problems (as the V17
// and V20 tests): kn = 1e7 N/m per m, kt = kn/2, critical damping ratio 0.3, rho = 2650.
core::ContactsEffectSpec SoftLatticeContacts(double dt_safety);

// The run's progress line on stderr: problem, size, choice, Pi_K, the error when it is known
// (the breakdown's is set once its real-water run is in), wall time and steps, then `detail`.
void PrintCoupledProgress(const AccuracyRun& row, const CoupledChoice& choice, int particles,
                          const std::string& detail, bool error_known = true);

// The walled hex lattice of the undrained and consolidation problems (as the V17 and V20 tests):
// `columns` x `rows` disks of radius 1 mm 1 um apart, soft lattice contacts, `walls`, local
// damping 0.3, flow with fluid forces and volume change, the fluid on the walls only, storage
// 0.14 V_d (the walled lattice's own V_p / V_d), implicit with the flow interval left to the DEM
// step (ApplyChoice sets the choice's solver).
inline constexpr double kLatticeStoragePorosity = 0.14;
core::SceneSpec WalledLattice(const std::string& name, std::uint32_t columns, std::uint32_t rows,
                              double viscosity_pa_s, core::WallsEffectSpec walls,
                              double end_time_s);

// For each choice, the index of the run it is compared with at real water: the base choice (real
// water, base_solver, automatic flow interval, the grid's first dt_safety) at the same size; the
// choice's own index when the grid has no such run.
std::vector<std::size_t> RealWaterBaseIndices(const std::vector<CoupledChoice>& choices,
                                              const CoupledGrid& grid);

// A report metric, NaN when absent.
double ReportMetric(const core::RunReport& report, const std::string& name);

}  // namespace seep::bench
