// SteadyStateSolver: the storage-free limit of the pressure equation (docs/physics.md §3.1, §4.4
// item 7),
//
//   sum_j C_ij (P_j - P_i) + Q_src,i = 0   for every non-fixed domain i,
//
// with fixed-pressure domains as Dirichlet data. The result is written into network.pressure().
//
// A component without a fixed-pressure node has no unique steady state. Policy:
//   kFail (default): FailedPrecondition naming the component and one of its domains;
//   kConserveStoredFluid: the component keeps its stored fluid sum V_s P (its pressure level is
//     fixed by the current pressures) — the long-time limit of the transient; requires its net
//     source to be zero (otherwise no steady state exists and the solve fails).
// Reuse as for ImplicitSolver: analysis per topology stamp, factorization per coefficient stamp.
#pragma once

#include <cstdint>
#include <memory>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/flow/linear_solver_kind.h"
#include "seep/core/flow/network_components.h"
#include "seep/core/status.h"

namespace seep::core {

namespace flow_internal {
class PressureSystem;
}

enum class ClosedComponentPolicy { kFail, kConserveStoredFluid };

struct SteadyStateOptions {
  LinearSolverKind linear_solver = LinearSolverKind::kCholmodSupernodal;
  ClosedComponentPolicy closed_components = ClosedComponentPolicy::kFail;
  StorageModel storage;  // only used to weight the conserved mean of closed components
};

struct SteadyStateReport {
  double boundary_inflow = 0.0;     // net rate into the network from fixed nodes, m^2/s
  double boundary_magnitude = 0.0;  // sum of |flux| over fixed-node pipes, m^2/s
  double source_inflow = 0.0;       // sum Q_src, m^2/s
  // |boundary_inflow + source_inflow| relative to the flux magnitudes plus what the boundary
  // pipes could carry at their pressures, sum C (|P_a| + |P_b|): how well the balance closes
  // compared with how finely the pressures resolve it (a state where nothing flows reports ~eps).
  double mass_balance_error = 0.0;
  double min_pressure = 0.0;
  double max_pressure = 0.0;
  std::int32_t num_components = 0;
  std::int32_t num_closed_components = 0;
};

class SteadyStateSolver {
 public:
  static Result<SteadyStateSolver> Create(const SteadyStateOptions& options);
  ~SteadyStateSolver();
  SteadyStateSolver(SteadyStateSolver&&) noexcept;
  SteadyStateSolver& operator=(SteadyStateSolver&&) noexcept;

  Result<SteadyStateReport> Solve(FlowNetwork& network);

  const LinearSystemStats& stats() const;

 private:
  explicit SteadyStateSolver(const SteadyStateOptions& options);
  Status PrepareTopology(const FlowNetwork& network);

  SteadyStateOptions options_;
  std::unique_ptr<flow_internal::PressureSystem> system_;
  std::uint64_t topology_stamp_ = 0;
  NetworkComponents components_;
  std::vector<std::uint8_t> pinned_;
};

// Convenience for one-off solves (no reuse across calls).
Result<SteadyStateReport> SolveSteadyState(FlowNetwork& network,
                                           const SteadyStateOptions& options = {});

}  // namespace seep::core
