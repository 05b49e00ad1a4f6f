#include "seep/core/scene/run_scene.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/log.h"
#include "seep/core/scene/scene_network.h"

namespace seep::core {
namespace {

// Progress reports per transient run when the scene does not choose an interval.
constexpr std::uint64_t kDefaultProgressReports = 200;

using Metrics = std::map<std::string, double>;

// Rate (m^2/s) at which fluid leaves fixed-pressure node `node` into the sample; 0 when no pipe
// joins it to a free domain. `domain` is sorted, as ComputeBoundaryFluxes emits it.
double NodeInflow(const BoundaryFluxes& fluxes, std::int32_t node) {
  const auto it = std::lower_bound(fluxes.domain.begin(), fluxes.domain.end(), node);
  if (it == fluxes.domain.end() || *it != node) return 0.0;
  return fluxes.inflow[static_cast<std::size_t>(it - fluxes.domain.begin())];
}

void AddPressureRange(const FlowNetwork& network, Metrics& m) {
  const PressureRange range = ComputePressureRange(network);
  m["min_pressure_pa"] = range.min;
  m["max_pressure_pa"] = range.max;
}

StorageModel StorageOf(const SceneSpec& scene) {
  StorageModel storage;
  storage.volume = scene.solver.storage == StorageVolumeKind::kPore ? StorageVolume::kPore
                                                                    : StorageVolume::kApparent;
  return storage;
}

// The exact permeability of a rigid lattice with uniform aperture a (physics.md §1.3, L = 2R).
std::optional<double> LatticePermeability(const SceneSpec& scene) {
  const auto* lattice = std::get_if<LatticePackingSpec>(&scene.packing.source);
  if (lattice == nullptr) return std::nullopt;
  const double a = scene.aperture.residual_aperture_m;
  const double k = a * a * a / (24.0 * lattice->radius_m);
  return lattice->kind == LatticeKind::kSquare ? k : k / std::sqrt(3.0);
}

void AddDarcyMetrics(const SceneSpec& scene, const SceneNetwork& net, Metrics& m) {
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  const double inflow = NodeInflow(fluxes, net.inlet_node);
  const double outflow = -NodeInflow(fluxes, net.outlet_node);
  m["inflow_m2_per_s"] = inflow;
  m["outflow_m2_per_s"] = outflow;
  const double dp = scene.boundary.inlet_pressure_pa - scene.boundary.outlet_pressure_pa;
  if (const auto k = DarcyPermeability(scene.fluid.viscosity_pa_s, 0.5 * (inflow + outflow),
                                       net.length_m, net.width_m, dp);
      k.ok()) {
    m["permeability_m2"] = *k;
    if (const auto exact = LatticePermeability(scene)) {
      m["lattice_permeability_m2"] = *exact;
      m["permeability_relative_error"] = std::abs(*k - *exact) / *exact;
    }
  }
  AddPressureRange(net.flow, m);
}

// Radial boundary: the rate out of the well into the sample and into the outer reservoir.
void AddRadialMetrics(const SceneNetwork& net, Metrics& m) {
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  m["well_flow_rate_m2_per_s"] = NodeInflow(fluxes, net.well_domain);
  m["outer_flow_rate_m2_per_s"] = -NodeInflow(fluxes, net.outer_node);
  m["outer_reservoir_radius_m"] = net.outer_reservoir_radius_m;
  m["well_area_m2"] = net.domains.apparent_volume[static_cast<std::size_t>(net.well_domain)];
  AddPressureRange(net.flow, m);
}

Status RunSteady(SceneNetwork& net, Metrics& m) {
  SEEP_ASSIGN_OR_RETURN(const SteadyStateReport report, SolveSteadyState(net.flow));
  m["mass_balance_error"] = report.mass_balance_error;
  return Status::Ok();
}

template <typename Solver>
Status RunTransient(const SceneSpec& scene, SceneNetwork& net, Solver& solver, double dt,
                    const RunControl& control, RunReport& run, Metrics& m) {
  const double end = scene.solver.end_time_s;
  const auto steps = static_cast<std::uint64_t>(std::ceil(end / dt * (1.0 - 1e-12)));
  const std::uint64_t every = scene.solver.progress_every > 0
                                  ? scene.solver.progress_every
                                  : std::max<std::uint64_t>(1, steps / kDefaultProgressReports);
  double worst_balance = 0.0;
  for (std::uint64_t s = 1; s <= steps; ++s) {
    if (control.stop.stop_requested()) {
      return Cancelled(fmt::format("run stopped at step {} of {}", run.steps, steps));
    }
    // The last step lands exactly on end_time_s.
    const double step_dt = s == steps ? end - run.time_s : dt;
    SEEP_ASSIGN_OR_RETURN(const FlowStepReport report, solver.Step(net.flow, step_dt));
    if (!std::isfinite(report.max_pressure) || !std::isfinite(report.min_pressure)) {
      return FailedPrecondition(fmt::format(
          "flow: pressure became non-finite at step {} (t = {} s); lower solver.dt_factor or use "
          "the implicit solver",
          s, run.time_s));
    }
    worst_balance = std::max(worst_balance, report.mass_balance_error);
    ++run.steps;
    run.time_s = s == steps ? end : run.time_s + report.dt;
    if (control.on_progress && (s % every == 0 || s == steps)) {
      control.on_progress(
          {run.steps, run.time_s, static_cast<double>(s) / static_cast<double>(steps)});
    }
  }
  m["mass_balance_error_max"] = worst_balance;
  return Status::Ok();
}

}  // namespace

Result<RunReport> RunScene(const SceneSpec& scene, const RunControl& control) {
  SEEP_RETURN_IF_ERROR(ValidateScene(scene));
  const auto log = control.logger ? control.logger : Logger();
  SEEP_ASSIGN_OR_RETURN(SceneNetwork net, BuildSceneNetwork(scene));
  if (scene.boundary.radial) {
    log->info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the outer reservoir; "
        "well domain {})",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.outer_pipes, net.well_domain);
  } else {
    log->info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the inlet, {} to the "
        "outlet)",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.inlet_pipes, net.outlet_pipes);
  }

  Metrics m;
  RunReport run;
  if (control.on_progress) control.on_progress({0, 0.0, 0.0});
  switch (scene.solver.kind) {
    case SolverKind::kSteady:
      SEEP_RETURN_IF_ERROR(RunSteady(net, m));
      break;
    case SolverKind::kExplicit:
    case SolverKind::kImplicit: {
      const StorageModel storage = StorageOf(scene);
      SEEP_ASSIGN_OR_RETURN(
          const CriticalTimeStep limit,
          ComputeCriticalTimeStep(net.flow, scene.fluid.bulk_modulus_pa, storage));
      if (!std::isfinite(limit.dt_crit)) {
        return FailedPrecondition("flow: no domain limits the time step (no pipes carry flow)");
      }
      const double dt = scene.solver.dt_factor * limit.dt_crit;
      m["dt_crit_s"] = limit.dt_crit;
      m["dt_s"] = dt;
      m["dt_over_dt_crit"] = scene.solver.dt_factor;
      m["limiting_domain"] = limit.limiting_domain;
      log->info(
          "{} solver: dt = {:.6g} s = {} x dt_crit (limiting domain {}), {} steps to t = {} s",
          scene.solver.kind == SolverKind::kExplicit ? "explicit" : "implicit", dt,
          scene.solver.dt_factor, limit.limiting_domain, std::ceil(scene.solver.end_time_s / dt),
          scene.solver.end_time_s);
      if (scene.solver.kind == SolverKind::kExplicit) {
        ExplicitSolverOptions options;
        options.bulk_modulus = scene.fluid.bulk_modulus_pa;
        options.storage = storage;
        options.safety_factor = 1.0;  // dt_factor <= 1 is checked by ValidateScene
        options.policy = StepLimitPolicy::kRefuse;
        SEEP_ASSIGN_OR_RETURN(ExplicitSolver solver, ExplicitSolver::Create(options));
        SEEP_RETURN_IF_ERROR(RunTransient(scene, net, solver, dt, control, run, m));
      } else {
        ImplicitSolverOptions options;
        options.bulk_modulus = scene.fluid.bulk_modulus_pa;
        options.storage = storage;
        SEEP_ASSIGN_OR_RETURN(ImplicitSolver solver, ImplicitSolver::Create(options));
        SEEP_RETURN_IF_ERROR(RunTransient(scene, net, solver, dt, control, run, m));
      }
      break;
    }
  }
  if (scene.solver.kind == SolverKind::kSteady) {
    run.steps = 1;
    if (control.on_progress) control.on_progress({1, 0.0, 1.0});
  }

  if (scene.boundary.radial) {
    AddRadialMetrics(net, m);
  } else {
    AddDarcyMetrics(scene, net, m);
    m["sample_length_m"] = net.length_m;
    m["sample_width_m"] = net.width_m;
  }
  double pore = 0.0;
  double apparent = 0.0;
  for (std::size_t d = 0; d < net.domains.num_domains(); ++d) {
    pore += net.domains.pore_volume[d];
    apparent += net.domains.apparent_volume[d];
  }
  m["particle_count"] = static_cast<double>(net.packing.size());
  m["contact_count"] = static_cast<double>(net.contacts.size());
  m["domain_count"] = static_cast<double>(net.domains.num_domains());
  m["pipe_count"] = static_cast<double>(net.flow.num_pipes());
  m["porosity_2d"] = apparent > 0.0 ? pore / apparent : 0.0;
  m["steps"] = static_cast<double>(run.steps);
  m["simulated_time_s"] = run.time_s;
  run.metrics.assign(m.begin(), m.end());
  return run;
}

}  // namespace seep::core
