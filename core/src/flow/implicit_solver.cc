// The theta-method pressure step in increment form with the per-component budget correction
// (see implicit_solver.h).
#include "seep/core/flow/implicit_solver.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>

#include "pressure_system.h"
#include "seep/core/flow/network_components.h"
#include "seep/core/flow/pipe_head.h"
#include "seep/core/flow/storage_volume.h"
#include "step_input.h"

namespace seep::core {

ImplicitSolver::ImplicitSolver(const ImplicitSolverOptions& options)
    : options_(options),
      system_(std::make_unique<flow_internal::PressureSystem>(options.linear_solver)) {}
ImplicitSolver::~ImplicitSolver() = default;
ImplicitSolver::ImplicitSolver(ImplicitSolver&&) noexcept = default;
ImplicitSolver& ImplicitSolver::operator=(ImplicitSolver&&) noexcept = default;

Result<ImplicitSolver> ImplicitSolver::Create(const ImplicitSolverOptions& options) {
  if (!(std::isfinite(options.bulk_modulus) && options.bulk_modulus > 0.0)) {
    return InvalidArgument("flow.implicit.bulk_modulus: must be finite and > 0 (got " +
                           flow_internal::FormatNumber(options.bulk_modulus) + ")");
  }
  SEEP_RETURN_IF_ERROR(ValidateStorageModel(options.storage));
  if (options.linear_solver != LinearSolverKind::kAuto &&
      options.linear_solver != LinearSolverKind::kCholmodSupernodal &&
      options.linear_solver != LinearSolverKind::kEigenSimplicialLdlt) {
    return InvalidArgument("flow.implicit.linear_solver: unknown kind");
  }
  // Below 1/2 the scheme is only conditionally stable (it would need the explicit limit back).
  if (!(options.theta >= 0.5 && options.theta <= 1.0)) {
    return InvalidArgument(
        "flow.implicit.theta: must be in [0.5, 1] (0.5 = Crank-Nicolson, 1 = backward Euler), "
        "got " +
        flow_internal::FormatNumber(options.theta));
  }
  return ImplicitSolver(options);
}

const LinearSystemStats& ImplicitSolver::stats() const { return system_->stats(); }

LinearSolverKind ImplicitSolver::linear_solver_in_use() const {
  return system_->linear_solver_in_use();
}

Status ImplicitSolver::Prepare(const FlowNetwork& network) {
  if (network.topology_version() == topology_stamp_ &&
      network.coefficient_version() == coefficient_stamp_) {
    return Status::Ok();
  }
  // A new topology is validated whole; a coefficient edit on a known one (the coupled loop's, at
  // every flow update) re-checks the values only, as the explicit solver does: the same values
  // are checked either way (Validate ends with ValidateCoefficients).
  const bool known_topology = network.topology_version() == topology_stamp_;
  // Until the refresh succeeds the stamps are 0 (never issued): a refresh refused half-way (the
  // storage capacities check each domain as they overwrite it) leaves caches that no network
  // is trusted with, not even a copy taken before the edit.
  topology_stamp_ = 0;
  coefficient_stamp_ = 0;
  SEEP_RETURN_IF_ERROR(known_topology ? network.ValidateCoefficients() : network.Validate());
  SEEP_RETURN_IF_ERROR(
      ComputeStorageCapacities(network, options_.storage, options_.bulk_modulus, &capacity_));
  SEEP_ASSIGN_OR_RETURN(limit_, ComputeCriticalTimeStep(network, options_.bulk_modulus,
                                                        options_.storage, {}, &limit_scratch_));
  storage_diagonal_dt_ = -1.0;
  SEEP_RETURN_IF_ERROR(system_->SyncTopology(network, {}));

  // Components of the unknowns (= the non-fixed domains: this solver pins nothing) and the pipes
  // that join them to known domains: functions of the topology, found again only when it
  // changes (a coupled step changes the coefficients at every flow update).
  const auto domain_of = system_->domain_of_unknown();
  if (!known_topology) {
    const NetworkComponents components = FindNetworkComponents(network);
    num_components_ = static_cast<std::size_t>(components.num_components);
    component_of_unknown_.resize(domain_of.size());
    for (std::size_t u = 0; u < domain_of.size(); ++u) {
      component_of_unknown_[u] = components.component_of_domain[domain_of[u]];
    }
    const auto unknown_of = system_->unknown_of_domain();
    const auto pa = network.pipe_domain_a();
    const auto pb = network.pipe_domain_b();
    boundary_pipes_.clear();
    for (std::size_t p = 0; p < pa.size(); ++p) {
      if ((unknown_of[pa[p]] >= 0) != (unknown_of[pb[p]] >= 0)) {
        boundary_pipes_.push_back(static_cast<std::int32_t>(p));
      }
    }
  }
  // Their capacities, for the per-component budget correction of Step.
  component_capacity_.assign(num_components_, 0.0);
  for (std::size_t u = 0; u < domain_of.size(); ++u) {
    component_capacity_[component_of_unknown_[u]] += capacity_[domain_of[u]];
  }
  topology_stamp_ = network.topology_version();
  coefficient_stamp_ = network.coefficient_version();
  return Status::Ok();
}

Result<FlowStepReport> ImplicitSolver::Step(FlowNetwork& network, double dt,
                                            std::span<const double> volume_change,
                                            FluidTally* tally) {
  const std::size_t nd = network.num_domains();
  SEEP_RETURN_IF_ERROR(
      flow_internal::CheckStepInput("implicit", dt, nd, volume_change, options_.diagnostics));
  SEEP_RETURN_IF_ERROR(flow_internal::CheckTally("implicit", nd, tally, options_.diagnostics));
  SEEP_RETURN_IF_ERROR(Prepare(network));
  const double theta = options_.theta;
  if (dt != storage_diagonal_dt_) {
    // S / (theta dt): the system is divided by theta so that its matrix is "storage + L_ff" as
    // for backward Euler (theta = 1 leaves every value bit-identical to the plain form).
    const double theta_dt = theta * dt;
    storage_diagonal_.resize(nd);
    for (std::size_t d = 0; d < nd; ++d) storage_diagonal_[d] = capacity_[d] / theta_dt;
    storage_diagonal_dt_ = dt;
  }
  SEEP_RETURN_IF_ERROR(
      system_->SyncValues(network, storage_diagonal_, network.coefficient_version(), dt));

  const auto domain_of = system_->domain_of_unknown();
  const auto unknown_of = system_->unknown_of_domain();
  const std::size_t nu = domain_of.size();
  const auto q_src = network.source_rate();
  const auto pressure_old = network.pressure();
  const auto pa = network.pipe_domain_a();
  const auto pb = network.pipe_domain_b();
  const auto c = network.pipe_conductance();
  // Fluid weight: the head part of each pipe's flow is constant over the step (pipe_head.h), so
  // it enters the right-hand side only; for a pipe with one known end, the head offset as seen
  // from its unknown end: q into u = C (P_known - P_u -/+ offset), - when u is the pipe's a.
  const bool weight = network.has_head_offsets();
  const auto offset = network.pipe_head_offset();
  const auto boundary_drive = [&](std::int32_t p, std::int32_t known, std::int32_t unknown,
                                  double increment) {
    const double drive = pressure_old[known] - pressure_old[unknown] - increment;
    if (!weight) return drive;
    return drive + (unknown == pa[p] ? -offset[p] : offset[p]);
  };

  // dV/dt per unknown, divided once: the budget correction below subtracts the same quotients.
  std::vector<double>& pore_growth_rate = pore_growth_rate_;
  pore_growth_rate.assign(volume_change.empty() ? 0 : nu, 0.0);
  for (std::size_t u = 0; u < pore_growth_rate.size(); ++u) {
    pore_growth_rate[u] = volume_change[domain_of[u]] / dt;
  }
  const bool growth = !pore_growth_rate.empty();
  // b = (F(P^n) + Q_src - dV/dt) / theta, F accumulated pipe by pipe in pipe order.
  Eigen::VectorXd& rhs = rhs_;
  rhs.resize(static_cast<Eigen::Index>(nu));
  for (std::size_t u = 0; u < nu; ++u) {
    double r = q_src[domain_of[u]];
    if (growth) r -= pore_growth_rate[u];
    rhs[static_cast<Eigen::Index>(u)] = r;
  }
  for (std::size_t p = 0; p < c.size(); ++p) {
    const int ua = unknown_of[pa[p]];
    const int ub = unknown_of[pb[p]];
    if (ua < 0 && ub < 0) continue;
    const double q = weight ? c[p] * (pressure_old[pb[p]] - pressure_old[pa[p]] - offset[p])
                            : c[p] * (pressure_old[pb[p]] - pressure_old[pa[p]]);  // a <- b
    if (ua >= 0) rhs[ua] += q;
    if (ub >= 0) rhs[ub] -= q;
  }
  if (theta != 1.0) rhs /= theta;
  Eigen::VectorXd& x = increment_;
  SEEP_RETURN_IF_ERROR(system_->Solve(rhs, x));

  // Per-component budget correction (see the header): alpha_c = R_c / D_c with, in units of
  // m^2/s (the theta-scaled equation times theta),
  //   R_c = sum_c (Q - dV/dt) + sum_bnd C (P_known - P_u^n - theta x_u) - sum_c S x / dt,
  //   D_c = sum_c S / dt + theta sum_bnd C.
  // Interior pipes do not appear: their fluxes cancel exactly in a component's sum.
  const std::size_t nc = component_capacity_.size();
  std::vector<double>& residual = residual_;
  std::vector<double>& denominator = denominator_;
  residual.assign(nc, 0.0);
  denominator.assign(nc, 0.0);
  for (std::size_t k = 0; k < nc; ++k) denominator[k] = component_capacity_[k] / dt;
  for (std::size_t u = 0; u < nu; ++u) {
    const std::int32_t d = domain_of[u];
    double r = q_src[d] - capacity_[d] * x[static_cast<Eigen::Index>(u)] / dt;
    if (growth) r -= pore_growth_rate[u];
    residual[component_of_unknown_[u]] += r;
  }
  for (const std::int32_t p : boundary_pipes_) {
    const int ua = unknown_of[pa[p]];
    const int u = ua >= 0 ? ua : unknown_of[pb[p]];
    const std::int32_t known = ua >= 0 ? pb[p] : pa[p];
    const std::int32_t k = component_of_unknown_[u];
    residual[k] += c[p] * boundary_drive(p, known, domain_of[u], theta * x[u]);
    denominator[k] += theta * c[p];
  }
  // alpha_c once per component (the same quotient for each of its unknowns).
  for (std::size_t k = 0; k < nc; ++k) residual[k] /= denominator[k];
  for (std::size_t u = 0; u < nu; ++u) {
    x[static_cast<Eigen::Index>(u)] += residual[component_of_unknown_[u]];
  }

  FlowStepReport report;
  report.dt = dt;
  report.dt_requested = dt;
  report.dt_crit = limit_.dt_crit;
  report.limiting_domain = limit_.limiting_domain;

  if (options_.diagnostics) {
    double stored = 0.0, stored_mag = 0.0, stored_level = 0.0, dv_sum = 0.0, dv_mag = 0.0,
           src = 0.0, src_mag = 0.0;
    for (std::size_t u = 0; u < nu; ++u) {
      const std::int32_t d = domain_of[u];
      const double dp = x[static_cast<Eigen::Index>(u)];
      const double s = capacity_[d] * dp;
      stored += s;
      stored_mag += std::abs(s);
      stored_level += capacity_[d] * std::abs(pressure_old[d] + dp);
      const double dv = volume_change.empty() ? 0.0 : volume_change[d];
      dv_sum += dv;
      dv_mag += std::abs(dv);
      src += q_src[d];
      src_mag += std::abs(q_src[d]);
    }
    // Boundary flux the scheme transports: theta q(P^{n+1}) + (1 - theta) q(P^n).
    double boundary = 0.0, boundary_mag = 0.0;
    for (const std::int32_t p : boundary_pipes_) {
      const int ua = unknown_of[pa[p]];
      const int u = ua >= 0 ? ua : unknown_of[pb[p]];
      const std::int32_t known = ua >= 0 ? pb[p] : pa[p];
      const double q = c[p] * boundary_drive(p, known, domain_of[u], theta * x[u]);
      boundary += q;
      boundary_mag += std::abs(q);
      if (tally != nullptr) tally->node_outflow_m2[known] -= dt * q;
    }
    if (tally != nullptr) {
      tally->source_m2 += dt * src;
      tally->compressed_m2 += stored;
      tally->pore_growth_m2 += dv_sum;
      tally->boundary_gross_m2 += dt * boundary_mag;
    }
    report.boundary_inflow = boundary;
    report.source_inflow = src;
    report.volume_change = dv_sum;
    report.stored_change = stored;
    const double expected = dt * (boundary + src) - dv_sum;
    const double scale = stored_level + stored_mag + dt * (boundary_mag + src_mag) + dv_mag;
    report.mass_balance_error = scale > 0.0 ? std::abs(stored - expected) / scale : 0.0;
  }

  auto pressure = network.mutable_pressure();
  for (std::size_t u = 0; u < nu; ++u) pressure[domain_of[u]] += x[static_cast<Eigen::Index>(u)];
  if (options_.diagnostics) {
    double lo = std::numeric_limits<double>::infinity();
    double hi = -lo;
    for (const double p : pressure) {
      lo = std::min(lo, p);
      hi = std::max(hi, p);
    }
    report.min_pressure = lo;
    report.max_pressure = hi;
    if (!(std::isfinite(lo) && std::isfinite(hi))) {
      return FailedPrecondition("flow.implicit: pressure became non-finite; check the dV input");
    }
  }
  return report;
}

}  // namespace seep::core
