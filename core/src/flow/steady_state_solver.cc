#include "seep/core/flow/steady_state_solver.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>

#include "pressure_system.h"
#include "seep/core/flow/pipe_head.h"
#include "seep/core/flow/storage_volume.h"
#include "step_input.h"
namespace seep::core {

SteadyStateSolver::SteadyStateSolver(const SteadyStateOptions& options)
    : options_(options),
      system_(std::make_unique<flow_internal::PressureSystem>(options.linear_solver)) {}
SteadyStateSolver::~SteadyStateSolver() = default;
SteadyStateSolver::SteadyStateSolver(SteadyStateSolver&&) noexcept = default;
SteadyStateSolver& SteadyStateSolver::operator=(SteadyStateSolver&&) noexcept = default;

Result<SteadyStateSolver> SteadyStateSolver::Create(const SteadyStateOptions& options) {
  if (options.linear_solver != LinearSolverKind::kAuto &&
      options.linear_solver != LinearSolverKind::kCholmodSupernodal &&
      options.linear_solver != LinearSolverKind::kEigenSimplicialLdlt) {
    return InvalidArgument("flow.steady.linear_solver: unknown kind");
  }
  if (options.closed_components != ClosedComponentPolicy::kFail &&
      options.closed_components != ClosedComponentPolicy::kConserveStoredFluid) {
    return InvalidArgument("flow.steady.closed_components: unknown policy");
  }
  SEEP_RETURN_IF_ERROR(ValidateStorageModel(options.storage));
  return SteadyStateSolver(options);
}

const LinearSystemStats& SteadyStateSolver::stats() const { return system_->stats(); }

Status SteadyStateSolver::PrepareTopology(const FlowNetwork& network) {
  if (network.topology_version() == topology_stamp_) return Status::Ok();
  topology_stamp_ = 0;
  components_ = FindNetworkComponents(network);
  pinned_.assign(network.num_domains(), 0);
  for (std::int32_t k = 0; k < components_.num_components; ++k) {
    if (components_.anchored[k]) continue;
    if (options_.closed_components == ClosedComponentPolicy::kFail) {
      return FailedPrecondition(
          "flow.steady: component " + std::to_string(k) + " (containing domain " +
          std::to_string(components_.first_domain[k]) +
          ") has no fixed-pressure domain, so its steady pressure is undefined (an isolated "
          "pocket); in a scene, hold a pressure on it (scene.boundary.regions: a fixed_pressure "
          "region around it) or run a transient solver (scene.solver.kind: explicit or "
          "implicit), which keeps the fluid the pocket holds; from C++, "
          "ClosedComponentPolicy::kConserveStoredFluid does the same in a steady solve");
    }
    pinned_[components_.first_domain[k]] = 1;  // gauge: solved relative to this domain
  }
  SEEP_RETURN_IF_ERROR(system_->SyncTopology(network, pinned_));
  topology_stamp_ = network.topology_version();
  return Status::Ok();
}

Result<SteadyStateReport> SteadyStateSolver::Solve(FlowNetwork& network) {
  SEEP_RETURN_IF_ERROR(network.Validate());  // O(n): negligible next to a factorization
  SEEP_RETURN_IF_ERROR(PrepareTopology(network));
  SEEP_RETURN_IF_ERROR(system_->SyncValues(network, {}, network.coefficient_version(), 0.0));

  const auto domain_of = system_->domain_of_unknown();
  const std::size_t nu = domain_of.size();
  const std::size_t nd = network.num_domains();
  const auto q_src = network.source_rate();
  const auto& comp = components_.component_of_domain;
  const auto nc = static_cast<std::size_t>(components_.num_components);

  // Closed components: the net source must vanish, and the stored fluid sum V_s P is kept.
  std::vector<double> closed_source(nc, 0.0), closed_source_mag(nc, 0.0);
  std::vector<double> closed_fluid(nc, 0.0), closed_storage(nc, 0.0);
  std::vector<double> vs;
  const bool any_closed =
      options_.closed_components == ClosedComponentPolicy::kConserveStoredFluid &&
      std::find(components_.anchored.begin(), components_.anchored.end(), 0) !=
          components_.anchored.end();
  if (any_closed) {
    SEEP_ASSIGN_OR_RETURN(vs, ComputeStorageVolumes(network, options_.storage));
    const auto pressure = network.pressure();
    for (std::size_t d = 0; d < nd; ++d) {
      if (comp[d] < 0 || components_.anchored[comp[d]]) continue;
      closed_source[comp[d]] += q_src[d];
      closed_source_mag[comp[d]] += std::abs(q_src[d]);
      closed_fluid[comp[d]] += vs[d] * pressure[d];
      closed_storage[comp[d]] += vs[d];
    }
    for (std::size_t k = 0; k < nc; ++k) {
      if (components_.anchored[k]) continue;
      if (std::abs(closed_source[k]) > 1e-12 * closed_source_mag[k]) {
        return FailedPrecondition(
            "flow.steady: closed component " + std::to_string(k) + " (containing domain " +
            std::to_string(components_.first_domain[k]) + ") has a net source of " +
            flow_internal::FormatNumber(closed_source[k]) + " m^2/s, so no steady state exists");
      }
    }
  }

  Eigen::VectorXd rhs(static_cast<Eigen::Index>(nu));
  for (std::size_t u = 0; u < nu; ++u) rhs[static_cast<Eigen::Index>(u)] = q_src[domain_of[u]];
  if (network.has_head_offsets()) {
    // Fluid weight: the head part of the pipe flows is a known inflow per domain (pipe_head.h).
    std::vector<double> head;
    ComputeHeadInflow(network, &head);
    for (std::size_t u = 0; u < nu; ++u) rhs[static_cast<Eigen::Index>(u)] += head[domain_of[u]];
  }
  system_->AddKnownCoupling(network, rhs);
  Eigen::VectorXd x;
  SEEP_RETURN_IF_ERROR(system_->Solve(rhs, x));

  auto pressure = network.mutable_pressure();
  for (std::size_t u = 0; u < nu; ++u) pressure[domain_of[u]] = x[static_cast<Eigen::Index>(u)];
  if (any_closed) {
    // Pinned domains sit at 0; shift each closed component to its conserved storage-weighted mean.
    for (std::size_t d = 0; d < nd; ++d) {
      if (system_->is_pinned(d)) pressure[d] = 0.0;
    }
    std::vector<double> solved_fluid(nc, 0.0);
    for (std::size_t d = 0; d < nd; ++d) {
      if (comp[d] >= 0 && !components_.anchored[comp[d]])
        solved_fluid[comp[d]] += vs[d] * pressure[d];
    }
    for (std::size_t d = 0; d < nd; ++d) {
      if (comp[d] < 0 || components_.anchored[comp[d]]) continue;
      const std::size_t k = static_cast<std::size_t>(comp[d]);
      pressure[d] += (closed_fluid[k] - solved_fluid[k]) / closed_storage[k];
    }
  }

  SteadyStateReport report;
  report.num_components = components_.num_components;
  for (const std::uint8_t a : components_.anchored) report.num_closed_components += a ? 0 : 1;
  const auto role = network.role();
  const auto pa = network.pipe_domain_a();
  const auto pb = network.pipe_domain_b();
  const auto c = network.pipe_conductance();
  double carrying = 0.0;
  for (std::size_t p = 0; p < c.size(); ++p) {
    const bool fa = role[pa[p]] == DomainRole::kFixedPressure;
    const bool fb = role[pb[p]] == DomainRole::kFixedPressure;
    if (fa == fb) continue;
    const double into_a = PipeInflowToA(network, p);
    const double q = fa ? -into_a : into_a;  // out of the fixed end into the network
    report.boundary_inflow += q;
    report.boundary_magnitude += std::abs(q);
    // Pressures resolved to a relative d move each boundary flow by up to d C (|P_a| + |P_b|):
    // without this term a state where nothing flows reports its noise relative to noise.
    carrying += c[p] * (std::abs(pressure[pa[p]]) + std::abs(pressure[pb[p]]));
    if (network.has_head_offsets()) carrying += c[p] * std::abs(network.pipe_head_offset()[p]);
  }
  double src_mag = 0.0;
  for (std::size_t d = 0; d < nd; ++d) {
    report.source_inflow += q_src[d];
    src_mag += std::abs(q_src[d]);
  }
  const double scale = report.boundary_magnitude + src_mag + carrying;
  report.mass_balance_error =
      scale > 0.0 ? std::abs(report.boundary_inflow + report.source_inflow) / scale : 0.0;
  report.min_pressure = std::numeric_limits<double>::infinity();
  report.max_pressure = -std::numeric_limits<double>::infinity();
  for (const double p : pressure) {
    report.min_pressure = std::min(report.min_pressure, p);
    report.max_pressure = std::max(report.max_pressure, p);
  }
  if (nd == 0) report.min_pressure = report.max_pressure = 0.0;
  return report;
}

Result<SteadyStateReport> SolveSteadyState(FlowNetwork& network,
                                           const SteadyStateOptions& options) {
  SEEP_ASSIGN_OR_RETURN(SteadyStateSolver solver, SteadyStateSolver::Create(options));
  return solver.Solve(network);
}

}  // namespace seep::core
