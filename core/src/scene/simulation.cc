#include "seep/core/scene/simulation.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <optional>

#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/log.h"

namespace seep::core {
namespace {

// Progress reports (and time-series samples) per transient run when the scene does not choose
// an interval.
constexpr std::uint64_t kDefaultProgressReports = 200;

using Metrics = std::map<std::string, double>;

// Rate (m^2/s) at which fluid leaves fixed-pressure node `node` into the sample; 0 when no pipe
// joins it to a free domain. `domain` is sorted, as ComputeBoundaryFluxes emits it.
double NodeInflow(const BoundaryFluxes& fluxes, std::int32_t node) {
  const auto it = std::lower_bound(fluxes.domain.begin(), fluxes.domain.end(), node);
  if (it == fluxes.domain.end() || *it != node) return 0.0;
  return fluxes.inflow[static_cast<std::size_t>(it - fluxes.domain.begin())];
}

// The rate into fixed-pressure node `node` out of the sample; 0 - x rather than -x, so that no
// flow reads 0 and not -0.
double NodeOutflow(const BoundaryFluxes& fluxes, std::int32_t node) {
  return 0.0 - NodeInflow(fluxes, node);
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
  const double outflow = NodeOutflow(fluxes, net.outlet_node);
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
  m["outer_flow_rate_m2_per_s"] = NodeOutflow(fluxes, net.outer_node);
  m["outer_reservoir_radius_m"] = net.outer_reservoir_radius_m;
  m["well_area_m2"] = net.domains.apparent_volume[static_cast<std::size_t>(net.well_domain)];
  AddPressureRange(net.flow, m);
}

// The time-series columns: the two boundary rates of the scene's boundary kind, the pressure
// range and the mass-balance error of the step that ended at the sample.
std::vector<std::string> SeriesColumns(const SceneSpec& scene) {
  if (scene.boundary.radial) {
    return {"time_s",          "well_flow_rate_m2_per_s", "outer_flow_rate_m2_per_s",
            "min_pressure_pa", "max_pressure_pa",         "mass_balance_error"};
  }
  return {"time_s",          "inflow_m2_per_s", "outflow_m2_per_s",
          "min_pressure_pa", "max_pressure_pa", "mass_balance_error"};
}

}  // namespace

Simulation::Simulation(SceneSpec scene, SceneNetwork net, std::shared_ptr<spdlog::logger> logger)
    : scene_(std::move(scene)), net_(std::move(net)), log_(std::move(logger)) {
  series_.columns = SeriesColumns(scene_);
}

Result<Simulation> Simulation::Create(const SceneSpec& scene,
                                      std::shared_ptr<spdlog::logger> logger) {
  SEEP_RETURN_IF_ERROR(ValidateScene(scene));
  if (!logger) logger = Logger();
  SEEP_ASSIGN_OR_RETURN(SceneNetwork net, BuildSceneNetwork(scene));
  if (scene.boundary.radial) {
    logger->info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the outer reservoir; "
        "well domain {})",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.outer_pipes, net.well_domain);
  } else {
    logger->info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the inlet, {} to the "
        "outlet)",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.inlet_pipes, net.outlet_pipes);
  }
  Simulation sim(scene, std::move(net), std::move(logger));
  if (scene.solver.kind != SolverKind::kSteady) SEEP_RETURN_IF_ERROR(sim.PrepareTransient());
  sim.Sample(0.0);  // the initial state is the first row
  return sim;
}

Status Simulation::PrepareTransient() {
  const StorageModel storage = StorageOf(scene_);
  SEEP_ASSIGN_OR_RETURN(const CriticalTimeStep limit,
                        ComputeCriticalTimeStep(net_.flow, scene_.fluid.bulk_modulus_pa, storage));
  if (!std::isfinite(limit.dt_crit)) {
    return FailedPrecondition("flow: no domain limits the time step (no pipes carry flow)");
  }
  dt_crit_ = limit.dt_crit;
  limiting_domain_ = limit.limiting_domain;
  dt_ = scene_.solver.dt_factor * limit.dt_crit;
  const double end = scene_.solver.end_time_s;
  total_steps_ = static_cast<std::uint64_t>(std::ceil(end / dt_ * (1.0 - 1e-12)));
  total_steps_ = std::max<std::uint64_t>(total_steps_, 1);
  sample_every_ = scene_.solver.progress_every > 0
                      ? scene_.solver.progress_every
                      : std::max<std::uint64_t>(1, total_steps_ / kDefaultProgressReports);
  log_->info("{} solver: dt = {:.6g} s = {} x dt_crit (limiting domain {}), {} steps to t = {} s",
             scene_.solver.kind == SolverKind::kExplicit ? "explicit" : "implicit", dt_,
             scene_.solver.dt_factor, limiting_domain_, total_steps_, end);
  if (scene_.solver.kind == SolverKind::kExplicit) {
    ExplicitSolverOptions options;
    options.bulk_modulus = scene_.fluid.bulk_modulus_pa;
    options.storage = storage;
    options.safety_factor = 1.0;  // dt_factor <= 1 is checked by ValidateScene
    options.policy = StepLimitPolicy::kRefuse;
    SEEP_ASSIGN_OR_RETURN(ExplicitSolver solver, ExplicitSolver::Create(options));
    solver_.emplace<ExplicitSolver>(std::move(solver));
  } else {
    ImplicitSolverOptions options;
    options.bulk_modulus = scene_.fluid.bulk_modulus_pa;
    options.storage = storage;
    SEEP_ASSIGN_OR_RETURN(ImplicitSolver solver, ImplicitSolver::Create(options));
    solver_.emplace<ImplicitSolver>(std::move(solver));
  }
  return Status::Ok();
}

void Simulation::Sample(double step_mass_balance_error) {
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net_.flow);
  const PressureRange range = ComputePressureRange(net_.flow);
  double first = 0.0;
  double second = 0.0;
  if (scene_.boundary.radial) {
    first = NodeInflow(fluxes, net_.well_domain);
    second = NodeOutflow(fluxes, net_.outer_node);
  } else {
    first = NodeInflow(fluxes, net_.inlet_node);
    second = NodeOutflow(fluxes, net_.outlet_node);
  }
  series_.values.insert(series_.values.end(),
                        {time_s_, first, second, range.min, range.max, step_mass_balance_error});
}

Status Simulation::StepOnce() {
  if (std::holds_alternative<std::monostate>(solver_)) {
    SEEP_ASSIGN_OR_RETURN(const SteadyStateReport report, SolveSteadyState(net_.flow));
    worst_mass_balance_ = report.mass_balance_error;
    step_ = 1;
    Sample(report.mass_balance_error);
    return Status::Ok();
  }
  const std::uint64_t s = step_ + 1;
  const double end = scene_.solver.end_time_s;
  // The last step lands on end_time_s: it is the time left, which the summed steps can make an
  // ulp longer than dt (that would exceed dt_crit at dt_factor 1), so never more than dt.
  const double step_dt = s == total_steps_ ? std::min(end - time_s_, dt_) : dt_;
  SEEP_ASSIGN_OR_RETURN(
      const FlowStepReport report,
      std::visit(
          [&](auto& solver) -> Result<FlowStepReport> {
            if constexpr (std::is_same_v<std::decay_t<decltype(solver)>, std::monostate>) {
              return Internal("no transient solver");
            } else {
              return solver.Step(net_.flow, step_dt);
            }
          },
          solver_));
  if (!std::isfinite(report.max_pressure) || !std::isfinite(report.min_pressure)) {
    return FailedPrecondition(fmt::format(
        "flow: pressure became non-finite at step {} (t = {} s); lower solver.dt_factor or use "
        "the implicit solver",
        s, time_s_));
  }
  worst_mass_balance_ = std::max(worst_mass_balance_, report.mass_balance_error);
  step_ = s;
  time_s_ = s == total_steps_ ? end : time_s_ + report.dt;
  if (s % sample_every_ == 0 || s == total_steps_) Sample(report.mass_balance_error);
  return Status::Ok();
}

Status Simulation::Run(const RunControl& control) {
  const auto fraction = [&] {
    return static_cast<double>(step_) / static_cast<double>(total_steps_);
  };
  if (control.on_progress) control.on_progress({step_, time_s_, fraction()});
  while (!finished()) {
    if (control.stop.stop_requested()) {
      return Cancelled(fmt::format("run stopped at step {} of {}", step_, total_steps_));
    }
    SEEP_RETURN_IF_ERROR(StepOnce());
    if (control.at_step_end) control.at_step_end(*this);
    if (control.on_progress && (step_ % sample_every_ == 0 || finished())) {
      control.on_progress({step_, time_s_, fraction()});
    }
  }
  return Status::Ok();
}

SimulationSnapshot Simulation::TakeSnapshot() const {
  SimulationSnapshot snap;
  snap.step = step_;
  snap.time_s = time_s_;
  snap.pressure.assign(net_.flow.pressure().begin(), net_.flow.pressure().end());
  snap.worst_mass_balance_error = worst_mass_balance_;
  snap.series = series_;
  return snap;
}

Status Simulation::Restore(const SimulationSnapshot& snap) {
  if (snap.pressure.size() != net_.flow.num_domains()) {
    return DataLoss(fmt::format(
        "snapshot.pressure: {} values for a network of {} nodes (not this scene's state)",
        snap.pressure.size(), net_.flow.num_domains()));
  }
  if (snap.step > total_steps_) {
    return DataLoss(fmt::format("snapshot.step: {} is past this scene's last step {}", snap.step,
                                total_steps_));
  }
  if (snap.series.columns != series_.columns ||
      snap.series.values.size() % series_.columns.size() != 0) {
    return DataLoss("snapshot.series: columns or row length differ from this scene's");
  }
  for (std::size_t i = 0; i < snap.pressure.size(); ++i) {
    if (!std::isfinite(snap.pressure[i])) {
      return DataLoss(fmt::format("snapshot.pressure[{}]: not finite", i));
    }
  }
  std::copy(snap.pressure.begin(), snap.pressure.end(), net_.flow.mutable_pressure().begin());
  step_ = snap.step;
  time_s_ = snap.time_s;
  worst_mass_balance_ = snap.worst_mass_balance_error;
  series_ = snap.series;
  return Status::Ok();
}

RunReport Simulation::Report() const {
  Metrics m;
  if (scene_.solver.kind == SolverKind::kSteady) {
    m["mass_balance_error"] = worst_mass_balance_;
  } else {
    m["dt_crit_s"] = dt_crit_;
    m["dt_s"] = dt_;
    m["dt_over_dt_crit"] = scene_.solver.dt_factor;
    m["limiting_domain"] = limiting_domain_;
    m["mass_balance_error_max"] = worst_mass_balance_;
  }
  if (scene_.boundary.radial) {
    AddRadialMetrics(net_, m);
  } else {
    AddDarcyMetrics(scene_, net_, m);
    m["sample_length_m"] = net_.length_m;
    m["sample_width_m"] = net_.width_m;
  }
  double pore = 0.0;
  double apparent = 0.0;
  for (std::size_t d = 0; d < net_.domains.num_domains(); ++d) {
    pore += net_.domains.pore_volume[d];
    apparent += net_.domains.apparent_volume[d];
  }
  m["particle_count"] = static_cast<double>(net_.packing.size());
  m["contact_count"] = static_cast<double>(net_.contacts.size());
  m["domain_count"] = static_cast<double>(net_.domains.num_domains());
  m["pipe_count"] = static_cast<double>(net_.flow.num_pipes());
  m["porosity_2d"] = apparent > 0.0 ? pore / apparent : 0.0;
  m["steps"] = static_cast<double>(step_);
  m["simulated_time_s"] = time_s_;
  RunReport run;
  run.metrics.assign(m.begin(), m.end());
  run.steps = step_;
  run.time_s = time_s_;
  run.series = series_;
  return run;
}

}  // namespace seep::core
