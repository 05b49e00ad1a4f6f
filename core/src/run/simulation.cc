#include "seep/core/run/simulation.h"

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
  if (net.well_domain >= 0) {
    m["well_area_m2"] = net.domains.apparent_volume[static_cast<std::size_t>(net.well_domain)];
  }
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

void LogNetwork(const SceneSpec& scene, const SceneNetwork& net, spdlog::logger& logger) {
  if (scene.boundary.radial) {
    logger.info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the outer reservoir; "
        "well domain {})",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.outer_pipes, net.well_domain);
  } else {
    logger.info(
        "network: {} particles, {} contacts, {} domains, {} pipes ({} to the inlet, {} to the "
        "outlet)",
        net.packing.size(), net.contacts.size(), net.domains.num_domains(), net.flow.num_pipes(),
        net.inlet_pipes, net.outlet_pipes);
  }
}

const std::vector<WallSpec>& WallsOf(const SceneSpec& scene) {
  static const std::vector<WallSpec> kNone;
  const auto* walls = FindEffect<WallsEffectSpec>(scene);
  return walls != nullptr ? walls->walls : kNone;
}

const char* SideName(WallSide side) {
  switch (side) {
    case WallSide::kLeft:
      return "left";
    case WallSide::kRight:
      return "right";
    case WallSide::kBottom:
      return "bottom";
    case WallSide::kTop:
      return "top";
  }
  return "unknown";
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
  const bool flow = HasFlow(scene);
  SceneNetwork net;
  if (flow) {
    SEEP_ASSIGN_OR_RETURN(net, BuildSceneNetwork(scene));
    LogNetwork(scene, net, *logger);
  } else {
    SEEP_ASSIGN_OR_RETURN(net.packing, BuildScenePacking(scene.packing));
    double radius_sum = 0.0;
    for (double r : net.packing.radius) radius_sum += r;
    net.mean_radius_m = radius_sum / static_cast<double>(net.packing.size());
  }
  if (HasMechanics(scene)) {
    Simulation sim(scene, SceneNetwork{}, std::move(logger));
    SEEP_RETURN_IF_ERROR(sim.PrepareCoupled(std::move(net), flow));
    sim.Sample(0.0);
    return sim;
  }
  Simulation sim(scene, std::move(net), std::move(logger));
  if (scene.solver.kind != SolverKind::kSteady) SEEP_RETURN_IF_ERROR(sim.PrepareTransient());
  sim.Sample(0.0);  // the initial state is the first row
  return sim;
}

Status Simulation::PrepareCoupled(SceneNetwork net, bool has_network) {
  SEEP_ASSIGN_OR_RETURN(coupled_, CoupledStepper::Create(scene_, std::move(net), has_network));
  const CoupledState& state = coupled_->state();
  dt_ = coupled_->dt();
  dt_crit_ = state.flow.dt_crit_s;
  limiting_domain_ = state.flow.limiting_domain;
  const double end = scene_.solver.end_time_s;
  total_steps_ =
      std::max<std::uint64_t>(1, static_cast<std::uint64_t>(std::ceil(end / dt_ * (1.0 - 1e-12))));
  sample_every_ = scene_.solver.progress_every > 0
                      ? scene_.solver.progress_every
                      : std::max<std::uint64_t>(1, total_steps_ / kDefaultProgressReports);
  series_.columns = has_network ? SeriesColumns(scene_) : std::vector<std::string>{"time_s"};
  series_.columns.push_back("bonds_broken");
  for (const char* column : {"position_m", "stress_pa"}) {
    for (const WallSpec& w : WallsOf(scene_)) {
      series_.columns.push_back(fmt::format("{}_wall_{}", SideName(w.side), column));
    }
  }
  std::string hooks;
  for (const Hook hook : {kForceHook, kPostForceHook, kEndOfStepHook}) {
    hooks += hooks.empty() ? "[" : "] [";
    for (const std::string_view name : coupled_->HookList(hook)) {
      hooks += fmt::format("{}{}", hooks.back() == '[' ? "" : " ", name);
    }
  }
  log_->info(
      "coupled run: {} particles, DEM dt = {:.6g} s, {} steps to t = {} s; flow every {} DEM "
      "step(s) (fluid dt_crit {:.6g} s); hooks force/post-force/end-of-step: {}]",
      state.particles.size(), dt_, total_steps_, end, coupled_->flow_every(), dt_crit_, hooks);
  return Status::Ok();
}

ParticleView Simulation::particles() const {
  if (coupled_) {
    const DemParticles& p = coupled_->state().particles;
    return ParticleView{p.x, p.y, p.radius};
  }
  return ViewOf(net_.packing);
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
             scene_.solver.kind == SolverKind::kExplicit        ? "explicit"
             : scene_.solver.kind == SolverKind::kCrankNicolson ? "crank-nicolson"
                                                                : "implicit",
             dt_, scene_.solver.dt_factor, limiting_domain_, total_steps_, end);
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
    options.theta = scene_.solver.kind == SolverKind::kCrankNicolson ? 0.5 : 1.0;
    SEEP_ASSIGN_OR_RETURN(ImplicitSolver solver, ImplicitSolver::Create(options));
    solver_.emplace<ImplicitSolver>(std::move(solver));
  }
  return Status::Ok();
}

void Simulation::Sample(double step_mass_balance_error) {
  if (coupled_ && !coupled_->state().has_network) {
    series_.values.push_back(time_s_);
  } else {
    SampleFlow(step_mass_balance_error);
  }
  if (!coupled_) return;
  const CoupledState& state = coupled_->state();
  series_.values.push_back(static_cast<double>(state.bonds_broken));
  const std::vector<WallSpec>& walls = WallsOf(scene_);
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const DemWall& wall = state.walls[w];
    const bool vertical = walls[w].side == WallSide::kLeft || walls[w].side == WallSide::kRight;
    series_.values.push_back(vertical ? wall.px : wall.py);
  }
  for (std::size_t w = 0; w < walls.size(); ++w) series_.values.push_back(state.wall_stress_pa[w]);
}

void Simulation::SampleFlow(double step_mass_balance_error) {
  const SceneNetwork& net = network();
  const BoundaryFluxes fluxes = ComputeBoundaryFluxes(net.flow);
  const PressureRange range = ComputePressureRange(net.flow);
  double first = 0.0;
  double second = 0.0;
  if (scene_.boundary.radial) {
    first = NodeInflow(fluxes, net.well_domain);
    second = NodeOutflow(fluxes, net.outer_node);
  } else {
    first = NodeInflow(fluxes, net.inlet_node);
    second = NodeOutflow(fluxes, net.outlet_node);
  }
  series_.values.insert(series_.values.end(),
                        {time_s_, first, second, range.min, range.max, step_mass_balance_error});
}

Status Simulation::StepCoupled() {
  const std::uint64_t s = step_ + 1;
  SEEP_RETURN_IF_ERROR(coupled_->Step(s, total_steps_));
  const CoupledState& state = coupled_->state();
  worst_mass_balance_ = state.flow.worst_mass_balance_error;
  step_ = s;
  time_s_ = static_cast<double>(s) * dt_;
  if (s % sample_every_ == 0 || s == total_steps_) Sample(state.flow.mass_balance_error);
  return Status::Ok();
}

Status Simulation::StepOnce() {
  if (coupled_) return StepCoupled();
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
  const FlowNetwork& flow = network().flow;
  snap.pressure.assign(flow.pressure().begin(), flow.pressure().end());
  if (coupled_) coupled_->SaveTo(&snap.mechanics.emplace());
  snap.worst_mass_balance_error = worst_mass_balance_;
  snap.series = series_;
  return snap;
}

Status Simulation::Restore(const SimulationSnapshot& snap) {
  if (coupled_.get() != nullptr && !snap.mechanics) {
    return DataLoss("snapshot.mechanics: missing; this scene's particles move");
  }
  if (!coupled_ && snap.mechanics) {
    return DataLoss("snapshot.mechanics: present, but this scene's particles do not move");
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
  if (coupled_) {
    SEEP_RETURN_IF_ERROR(coupled_->RestoreFrom(*snap.mechanics));
    FlowNetwork& flow = coupled_->mutable_network().flow;
    if (snap.pressure.size() != flow.num_domains()) {
      return DataLoss(fmt::format(
          "snapshot.pressure: {} values for a network of {} nodes (not this scene's state)",
          snap.pressure.size(), flow.num_domains()));
    }
    std::copy(snap.pressure.begin(), snap.pressure.end(), flow.mutable_pressure().begin());
    step_ = snap.step;
    time_s_ = snap.time_s;
    worst_mass_balance_ = snap.worst_mass_balance_error;
    series_ = snap.series;
    return Status::Ok();
  }
  if (snap.pressure.size() != net_.flow.num_domains()) {
    return DataLoss(fmt::format(
        "snapshot.pressure: {} values for a network of {} nodes (not this scene's state)",
        snap.pressure.size(), net_.flow.num_domains()));
  }
  std::copy(snap.pressure.begin(), snap.pressure.end(), net_.flow.mutable_pressure().begin());
  step_ = snap.step;
  time_s_ = snap.time_s;
  worst_mass_balance_ = snap.worst_mass_balance_error;
  series_ = snap.series;
  return Status::Ok();
}

void Simulation::AddCoupledMetrics(Metrics& m) const {
  const CoupledState& state = coupled_->state();
  const EffectCounters& c = state.counters;
  m["dem_dt_s"] = dt_;
  if (std::isfinite(state.fluid_limited_dt)) m["fluid_limited_dt_s"] = state.fluid_limited_dt;
  m["flow_every_steps"] = static_cast<double>(coupled_->flow_every());
  m["bonds_broken"] = static_cast<double>(state.bonds_broken);
  m["redetections"] = static_cast<double>(c.redetections);
  m["particle_count"] = static_cast<double>(state.particles.size());
  if (state.has_network) {
    // Sub-cycles per DEM step: flow sub-steps of the largest update over its DEM steps.
    m["flow_sub_steps_max"] = static_cast<double>(state.flow.max_sub_steps);
    m["flow_sub_steps_per_dem_step_max"] =
        static_cast<double>(state.flow.max_sub_steps) / static_cast<double>(coupled_->flow_every());
    m["dt_crit_s"] = state.flow.dt_crit_s;
    m["limiting_domain"] = state.flow.limiting_domain;
    m["mass_balance_error_max"] = state.flow.worst_mass_balance_error;
  }
  if (state.injection_rate_m2_s > 0.0) {
    m["breakdown_pressure_pa"] = state.peak_well_pressure_pa;
    m["breakdown_time_s"] = state.peak_well_time_s;
    if (state.net.well_domain >= 0) {
      m["well_pressure_pa"] =
          state.net.flow.pressure()[static_cast<std::size_t>(state.net.well_domain)];
    }
    if (state.breakthrough_time_s >= 0.0) m["breakthrough_time_s"] = state.breakthrough_time_s;
  }
  const std::vector<WallSpec>& walls = WallsOf(scene_);
  for (std::size_t w = 0; w < walls.size(); ++w) {
    const DemWall& wall = state.walls[w];
    const bool vertical = walls[w].side == WallSide::kLeft || walls[w].side == WallSide::kRight;
    m[fmt::format("{}_wall_position_m", SideName(walls[w].side))] = vertical ? wall.px : wall.py;
    m[fmt::format("{}_wall_stress_pa", SideName(walls[w].side))] = state.wall_stress_pa[w];
  }
  double kinetic = 0.0;
  const DemParticles& p = state.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    kinetic += 0.5 * p.mass[i] * (p.vx[i] * p.vx[i] + p.vy[i] * p.vy[i]) +
               0.5 * p.inertia[i] * p.omega[i] * p.omega[i];
  }
  m["kinetic_energy_j_per_m"] = kinetic;
  m["steps"] = static_cast<double>(step_);
  m["simulated_time_s"] = time_s_;
}

RunReport Simulation::Report() const {
  Metrics m;
  if (coupled_) {
    AddCoupledMetrics(m);
    if (coupled_->state().has_network) AddNetworkMetrics(m);
    RunReport run;
    run.metrics.assign(m.begin(), m.end());
    run.steps = step_;
    run.time_s = time_s_;
    run.series = series_;
    return run;
  }
  if (scene_.solver.kind == SolverKind::kSteady) {
    m["mass_balance_error"] = worst_mass_balance_;
  } else {
    m["dt_crit_s"] = dt_crit_;
    m["dt_s"] = dt_;
    m["dt_over_dt_crit"] = scene_.solver.dt_factor;
    m["limiting_domain"] = limiting_domain_;
    m["mass_balance_error_max"] = worst_mass_balance_;
  }
  AddNetworkMetrics(m);
  m["steps"] = static_cast<double>(step_);
  m["simulated_time_s"] = time_s_;
  RunReport run;
  run.metrics.assign(m.begin(), m.end());
  run.steps = step_;
  run.time_s = time_s_;
  run.series = series_;
  return run;
}

std::vector<double> Simulation::PoreVolumes() const {
  if (coupled_) return coupled_->ReportedPoreVolumes();
  const auto pore = net_.flow.pore_volume();
  return {pore.begin(), pore.end()};
}

void Simulation::AddNetworkMetrics(Metrics& m) const {
  const SceneNetwork& net = network();
  if (scene_.boundary.radial) {
    AddRadialMetrics(net, m);
  } else {
    AddDarcyMetrics(scene_, net, m);
    m["sample_length_m"] = net.length_m;
    m["sample_width_m"] = net.width_m;
  }
  const std::vector<double> pore_volume = PoreVolumes();
  double pore = 0.0;
  double apparent = 0.0;
  for (std::size_t d = 0; d < net.domains.num_domains(); ++d) {
    pore += pore_volume[d];
    apparent += net.domains.apparent_volume[d];
  }
  m["particle_count"] = static_cast<double>(net.packing.size());
  m["contact_count"] = static_cast<double>(net.contacts.size());
  m["domain_count"] = static_cast<double>(net.domains.num_domains());
  m["pipe_count"] = static_cast<double>(net.flow.num_pipes());
  m["porosity_2d"] = apparent > 0.0 ? pore / apparent : 0.0;
}

}  // namespace seep::core
