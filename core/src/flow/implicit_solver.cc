#include "seep/core/flow/implicit_solver.h"

#include <cmath>
#include <sstream>
#include <string>

#include "pressure_system.h"
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
  if (options.linear_solver != LinearSolverKind::kCholmodSupernodal &&
      options.linear_solver != LinearSolverKind::kEigenSimplicialLdlt) {
    return InvalidArgument("flow.implicit.linear_solver: unknown kind");
  }
  return ImplicitSolver(options);
}

const LinearSystemStats& ImplicitSolver::stats() const { return system_->stats(); }

Status ImplicitSolver::Prepare(const FlowNetwork& network) {
  if (network.topology_version() == topology_stamp_ &&
      network.coefficient_version() == coefficient_stamp_) {
    return Status::Ok();
  }
  SEEP_RETURN_IF_ERROR(network.Validate());
  SEEP_ASSIGN_OR_RETURN(capacity_,
                        ComputeStorageCapacities(network, options_.storage, options_.bulk_modulus));
  SEEP_ASSIGN_OR_RETURN(limit_,
                        ComputeCriticalTimeStep(network, options_.bulk_modulus, options_.storage));
  storage_diagonal_dt_ = -1.0;
  SEEP_RETURN_IF_ERROR(system_->SyncTopology(network, {}));
  topology_stamp_ = network.topology_version();
  coefficient_stamp_ = network.coefficient_version();
  return Status::Ok();
}

Result<FlowStepReport> ImplicitSolver::Step(FlowNetwork& network, double dt,
                                            std::span<const double> volume_change) {
  const std::size_t nd = network.num_domains();
  SEEP_RETURN_IF_ERROR(
      flow_internal::CheckStepInput("implicit", dt, nd, volume_change, options_.diagnostics));
  SEEP_RETURN_IF_ERROR(Prepare(network));
  if (dt != storage_diagonal_dt_) {
    storage_diagonal_.resize(nd);
    for (std::size_t d = 0; d < nd; ++d) storage_diagonal_[d] = capacity_[d] / dt;
    storage_diagonal_dt_ = dt;
  }
  SEEP_RETURN_IF_ERROR(
      system_->SyncValues(network, storage_diagonal_, network.coefficient_version(), dt));

  const auto domain_of = system_->domain_of_unknown();
  const std::size_t nu = domain_of.size();
  const auto q_src = network.source_rate();
  const auto pressure_old = network.pressure();
  Eigen::VectorXd rhs(static_cast<Eigen::Index>(nu));
  for (std::size_t u = 0; u < nu; ++u) {
    const std::int32_t d = domain_of[u];
    double r = storage_diagonal_[d] * pressure_old[d] + q_src[d];
    if (!volume_change.empty()) r -= volume_change[d] / dt;
    rhs[static_cast<Eigen::Index>(u)] = r;
  }
  system_->AddKnownCoupling(network, rhs);
  Eigen::VectorXd x;
  SEEP_RETURN_IF_ERROR(system_->Solve(rhs, x));

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
      const double s = capacity_[d] * (x[static_cast<Eigen::Index>(u)] - pressure_old[d]);
      stored += s;
      stored_mag += std::abs(s);
      stored_level += capacity_[d] * std::abs(x[static_cast<Eigen::Index>(u)]);
      const double dv = volume_change.empty() ? 0.0 : volume_change[d];
      dv_sum += dv;
      dv_mag += std::abs(dv);
      src += q_src[d];
      src_mag += std::abs(q_src[d]);
    }
    // Boundary flux at the new pressures: what backward Euler transports.
    const auto pa = network.pipe_domain_a();
    const auto pb = network.pipe_domain_b();
    const auto c = network.pipe_conductance();
    const auto unknown_of = system_->unknown_of_domain();
    double boundary = 0.0, boundary_mag = 0.0;
    for (std::size_t p = 0; p < c.size(); ++p) {
      const int ua = unknown_of[pa[p]];
      const int ub = unknown_of[pb[p]];
      if ((ua >= 0) == (ub >= 0)) continue;
      const double q =
          ua >= 0 ? c[p] * (pressure_old[pb[p]] - x[ua]) : c[p] * (pressure_old[pa[p]] - x[ub]);
      boundary += q;
      boundary_mag += std::abs(q);
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
  for (std::size_t u = 0; u < nu; ++u) pressure[domain_of[u]] = x[static_cast<Eigen::Index>(u)];
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
