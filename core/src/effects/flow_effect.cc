#include "seep/core/effects/flow_effect.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <span>

#include "network_report.h"
#include "platen_permeameter.h"
#include "seep/core/effects/effect_set.h"
#include "seep/core/effects/volume_change_effect.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/network/boundary_regions.h"
#include "seep/core/network/fluid_boundaries.h"

namespace seep::core {
namespace {

Status CheckFinite(const FlowStepReport& r, const StepInfo& info) {
  if (std::isfinite(r.min_pressure) && std::isfinite(r.max_pressure)) return Status::Ok();
  return FailedPrecondition(fmt::format(
      "flow: pressure became non-finite at step {} (t = {} s); lower solver.dt_factor or use "
      "the implicit solver",
      info.step, info.time_s));
}

// The run's books (fluid_ledger.h): fluid_injected_m2, fluid_left_<boundary>_m2 per boundary,
// fluid_stored_m2 (= compressed + pore growth), fluid_redetection_m2, fluid_handled_m2 and
// fluid_balance_error, |imbalance| / handled.
void AddLedgerMetrics(std::span<const std::string> names, const FluidLedger& ledger, Metrics* m) {
  (*m)["fluid_injected_m2"] = ledger.injected_m2;
  for (std::size_t b = 0; b < names.size() && b < ledger.left_m2.size(); ++b) {
    (*m)[fmt::format("fluid_left_{}_m2", names[b])] = ledger.left_m2[b];
  }
  (*m)["fluid_stored_m2"] = ledger.stored_m2();
  (*m)["fluid_compressed_m2"] = ledger.compressed_m2;
  (*m)["fluid_pore_growth_m2"] = ledger.pore_growth_m2;
  (*m)["fluid_redetection_m2"] = ledger.redetection_m2;
  (*m)["fluid_handled_m2"] = ledger.handled_m2;
  (*m)["fluid_balance_error"] = ledger.relative_error();
  if (ledger.since_step > 0)
    (*m)["fluid_books_since_step"] = static_cast<double>(ledger.since_step);
}

}  // namespace

Status FlowEffect::RefreshFluidWeight(LiveState& s) {
  if (!weight_ || !s.has_network) return Status::Ok();
  const ParticleView positions =
      s.moves() ? s.step_vertices.CurrentInStep(s) : ViewOf(s.net.packing);
  SEEP_RETURN_IF_ERROR(ComputeNodeWeightPressures(s.net, positions, *weight_, &node_weight_));
  return ApplyHeadOffsets(node_weight_, &s.net.flow);
}

Status FlowEffect::MapBoundaries(const LiveState& s) {
  boundary_nodes_.clear();
  if (mode_ == FlowMode::kSteady || !s.has_network) return Status::Ok();
  SEEP_ASSIGN_OR_RETURN(const std::vector<std::int32_t> of, FluidBoundaryOfNodes(*s.scene, s.net));
  for (std::size_t d = 0; d < of.size(); ++d) {
    if (of[d] >= 0) boundary_nodes_.emplace_back(static_cast<std::int32_t>(d), of[d]);
  }
  tally_.Reset(s.net.flow.num_domains());
  return Status::Ok();
}

void FlowEffect::Book(FluidLedger& ledger) {
  ledger.injected_m2 += tally_.source_m2;
  ledger.compressed_m2 += tally_.compressed_m2;
  ledger.pore_growth_m2 += tally_.pore_growth_m2;
  // A flux region that extracts is a negative source: what it moved counts all the same.
  ledger.handled_m2 += std::abs(tally_.source_m2) + tally_.boundary_gross_m2;
  for (const auto& [node, boundary] : boundary_nodes_) {
    double& out = tally_.node_outflow_m2[static_cast<std::size_t>(node)];
    ledger.left_m2[static_cast<std::size_t>(boundary)] += out;
    out = 0.0;
  }
  tally_.source_m2 = tally_.compressed_m2 = tally_.pore_growth_m2 = tally_.boundary_gross_m2 = 0.0;
}

Status FlowEffect::Rebind(LiveState& s) {
  SEEP_RETURN_IF_ERROR(MapBoundaries(s));
  return RefreshFluidWeight(s);
}

Status FlowEffect::Reconfigure(LiveState& s) {
  if (!s.has_network) return Status::Ok();
  SetBoundaryPressures(*s.scene, &s.net);
  return SetRegionConditions(*s.scene, &s.net);
}

Status FlowEffect::Bind(LiveState& s, const EffectSet& effects) {
  const SceneSpec& scene = *s.scene;
  volume_change_ = effects.volume_change;
  if (s.moves()) {
    mode_ = FlowMode::kSubCycled;
  } else {
    mode_ = scene.solver.kind == SolverKind::kSteady ? FlowMode::kSteady : FlowMode::kStepped;
  }
  if (const auto pair = effects_internal::FindPlatenPair(scene)) {
    platens_ = std::pair{pair->high, pair->low};
    platens_along_x_ = pair->along_x;
  }
  weight_ = SceneFluidWeight(scene);
  SEEP_RETURN_IF_ERROR(RefreshFluidWeight(s));
  if (weight_ && s.has_network && scene.boundary.initial_pressure_hydrostatic) {
    ApplyHydrostaticStart(scene, *weight_, node_weight_, &s.net);
  }
  if (mode_ == FlowMode::kSteady) return Status::Ok();
  boundary_names_ = FluidBoundaryNames(scene);
  s.books.ledger.left_m2.assign(boundary_names_.size(), 0.0);
  SEEP_RETURN_IF_ERROR(MapBoundaries(s));
  const StorageModel& storage = s.storage;
  if (scene.solver.kind == SolverKind::kExplicit) {
    ExplicitSolverOptions options;
    options.bulk_modulus = scene.fluid.bulk_modulus_pa;
    options.storage = storage;
    // Stepped: the step is dt_factor x dt_crit, so the governor passes it and refuses only a
    // network that changed under it; sub-cycled: the sub-steps are cut to it.
    options.safety_factor = scene.solver.dt_factor;
    options.policy = StepLimitPolicy::kRefuse;
    SEEP_ASSIGN_OR_RETURN(ExplicitSolver solver, ExplicitSolver::Create(options));
    solver_.emplace<ExplicitSolver>(std::move(solver));
  } else {
    ImplicitSolverOptions options;
    options.bulk_modulus = scene.fluid.bulk_modulus_pa;
    options.storage = storage;
    options.theta = scene.solver.kind == SolverKind::kCrankNicolson ? 0.5 : 1.0;
    options.linear_solver = scene.solver.linear_solver;
    SEEP_ASSIGN_OR_RETURN(ImplicitSolver solver, ImplicitSolver::Create(options));
    solver_.emplace<ImplicitSolver>(std::move(solver));
  }
  SEEP_ASSIGN_OR_RETURN(const CriticalTimeStep limit,
                        ComputeCriticalTimeStep(s.net.flow, scene.fluid.bulk_modulus_pa, storage));
  state_.dt_crit_s = limit.dt_crit;
  state_.limiting_domain = limit.limiting_domain;
  return Status::Ok();
}

std::uint64_t FlowEffect::SetEverySteps(double dem_dt, double fluid_limited_dt, double dt_factor) {
  every_steps_ = 1;
  if (spec_.every_steps > 0) {
    every_steps_ = spec_.every_steps;
  } else {
    // The interval also stays within the step the fluid's stiffness allows: a pressure that
    // lags the deformation by more acts as a delayed spring and pumps energy into the particles.
    const double interval = std::min(dt_factor * state_.dt_crit_s, fluid_limited_dt);
    const double fit = interval / dem_dt;
    if (fit >= 1.0) every_steps_ = static_cast<std::uint64_t>(std::min(fit, 1e6));
  }
  return every_steps_;
}

Status FlowEffect::UpdateFlow(LiveState& s, const StepInfo& info) {
  if (!info.flow_update) return Status::Ok();
  double error = 0.0;
  std::int64_t sub_steps = 1;
  // dV over the interval (moving particles with volume_change), else rigid.
  const std::span<const double> dv =
      volume_change_ != nullptr ? volume_change_->change() : std::span<const double>{};
  // The centroids moved with the particles: the heads of this update are measured from here.
  if (mode_ == FlowMode::kSubCycled) SEEP_RETURN_IF_ERROR(RefreshFluidWeight(s));
  if (mode_ == FlowMode::kSteady) {
    SteadyStateOptions steady;
    steady.linear_solver = s.scene->solver.linear_solver;
    SEEP_ASSIGN_OR_RETURN(const SteadyStateReport report, SolveSteadyState(s.net.flow, steady));
    error = report.mass_balance_error;
  } else if (auto* explicit_solver = std::get_if<ExplicitSolver>(&solver_)) {
    if (mode_ == FlowMode::kStepped) {
      SEEP_ASSIGN_OR_RETURN(const FlowStepReport report,
                            explicit_solver->Step(s.net.flow, info.flow_dt, {}, &tally_));
      SEEP_RETURN_IF_ERROR(CheckFinite(report, info));
      error = report.mass_balance_error;
    } else {
      SEEP_ASSIGN_OR_RETURN(const FlowAdvanceReport report,
                            explicit_solver->Advance(s.net.flow, info.flow_dt, dv, &tally_));
      SEEP_RETURN_IF_ERROR(CheckFinite(report.last, info));
      error = report.max_mass_balance_error;
      sub_steps = report.sub_steps;
      state_.dt_crit_s = report.dt_crit;
      state_.limiting_domain = report.limiting_domain;
    }
  } else {
    SEEP_ASSIGN_OR_RETURN(const FlowStepReport report, std::get<ImplicitSolver>(solver_).Step(
                                                           s.net.flow, info.flow_dt, dv, &tally_));
    SEEP_RETURN_IF_ERROR(CheckFinite(report, info));
    error = report.mass_balance_error;
    if (mode_ == FlowMode::kSubCycled) {
      state_.dt_crit_s = report.dt_crit;
      state_.limiting_domain = report.limiting_domain;
    }
  }
  if (mode_ != FlowMode::kSteady) {
    Book(s.books.ledger);
    // The fluid the pores' deformation moved counts as handled too: a sealed sample squeezed
    // with nothing flowing in or out moves fluid all the same, and its books' error is relative
    // to that (relative to the rounding of a remap alone it read 0.1 to 0.8).
    const auto role = s.net.flow.role();
    double deformation = 0.0;
    for (std::size_t d = 0; d < dv.size(); ++d) {
      if (role[d] != DomainRole::kFixedPressure) deformation += std::abs(dv[d]);
    }
    s.books.ledger.handled_m2 += deformation;
  }
  ++s.counters.flow_updates;
  s.counters.flow_sub_steps += static_cast<std::uint64_t>(sub_steps);
  s.books.step_error = error;
  s.books.worst_error = std::max(s.books.worst_error, error);
  state_.max_sub_steps = std::max(state_.max_sub_steps, sub_steps);
  return Status::Ok();
}

void FlowEffect::AddMetrics(const LiveState& s, Metrics* m) const {
  switch (mode_) {
    case FlowMode::kSteady:
      (*m)["mass_balance_error"] = s.books.worst_error;
      break;
    case FlowMode::kStepped:
      (*m)["dt_crit_s"] = state_.dt_crit_s;
      (*m)["dt_over_dt_crit"] = s.scene->solver.dt_factor;
      (*m)["limiting_domain"] = state_.limiting_domain;
      (*m)["mass_balance_error_max"] = s.books.worst_error;
      break;
    case FlowMode::kSubCycled:
      // Sub-cycles per DEM step: flow sub-steps of the largest update over its DEM steps.
      (*m)["flow_sub_steps_max"] = static_cast<double>(state_.max_sub_steps);
      (*m)["flow_sub_steps_per_dem_step_max"] =
          static_cast<double>(state_.max_sub_steps) / static_cast<double>(every_steps_);
      (*m)["dt_crit_s"] = state_.dt_crit_s;
      (*m)["limiting_domain"] = state_.limiting_domain;
      (*m)["mass_balance_error_max"] = s.books.worst_error;
      break;
  }
  effects_internal::AddNetworkMetrics(*s.scene, s.net, ReportedPoreVolumes(s, volume_change_),
                                      node_weight_, m);
  if (mode_ != FlowMode::kSteady) AddLedgerMetrics(boundary_names_, s.books.ledger, m);
  if (platens_) {
    if (const double k = PlatenPermeability(s); std::isfinite(k)) {
      (*m)["platen_permeability_m2"] = k;
    }
  }
}

double FlowEffect::PlatenPermeability(const LiveState& s) const {
  return effects_internal::PlatenPermeability(
      s, {platens_->first, platens_->second, platens_along_x_});
}

void FlowEffect::AddSeriesColumns(const LiveState& s, std::vector<std::string>* columns) const {
  effects_internal::AddNetworkSeriesColumns(*s.scene, columns);
  if (platens_) columns->push_back("platen_permeability_m2");
}

void FlowEffect::AddSample(const LiveState& s, std::vector<double>* row) const {
  effects_internal::AddNetworkSample(*s.scene, s.net, s.books.step_error, row);
  if (platens_) row->push_back(PlatenPermeability(s));
}

}  // namespace seep::core
