// ImplicitSolver: backward Euler on the pipe network (physics.md §4.5), unconditionally stable and
// monotone (the system matrix is an SPD M-matrix):
//
//   (V_s,i/K_f)(P_i^{n+1} - P_i^n)/dt = sum_j C_ij (P_j^{n+1} - P_i^{n+1}) + Q_src,i - dV_i/dt
//
// for every non-fixed domain; fixed-pressure domains enter the right-hand side. Closed components
// (no fixed node) are fine here: the storage term keeps the system definite.
//
// Reuse: the symbolic analysis is redone only when the network's topology stamp changes, the
// numeric factorization only when its coefficient stamp or dt changes; otherwise a step is one
// right-hand side and one back-substitution. stats() counts each stage.
#pragma once

#include <memory>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/flow_step_report.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/flow/linear_solver_kind.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/status.h"

namespace seep::core {

namespace flow_internal {
class PressureSystem;
}

struct ImplicitSolverOptions {
  double bulk_modulus = 2e9;  // K_f, Pa.
  StorageModel storage;
  LinearSolverKind linear_solver = LinearSolverKind::kCholmodSupernodal;
  bool diagnostics = true;  // validate dV and fill the budget part of the report
};

class ImplicitSolver {
 public:
  static Result<ImplicitSolver> Create(const ImplicitSolverOptions& options);
  ~ImplicitSolver();
  ImplicitSolver(ImplicitSolver&&) noexcept;
  ImplicitSolver& operator=(ImplicitSolver&&) noexcept;

  // One backward-Euler step of dt seconds. volume_change: dV_i over the step (m^2), empty = rigid.
  // The report carries dt_crit of the explicit scheme for reference (dt / dt_crit = how much the
  // implicit step buys).
  Result<FlowStepReport> Step(FlowNetwork& network, double dt,
                              std::span<const double> volume_change = {});

  const LinearSystemStats& stats() const;
  const ImplicitSolverOptions& options() const { return options_; }

 private:
  explicit ImplicitSolver(const ImplicitSolverOptions& options);
  Status Prepare(const FlowNetwork& network);

  ImplicitSolverOptions options_;
  std::unique_ptr<flow_internal::PressureSystem> system_;
  std::uint64_t topology_stamp_ = 0;
  std::uint64_t coefficient_stamp_ = 0;
  CriticalTimeStep limit_;
  std::vector<double> capacity_;  // V_s / K_f per domain (0 for fixed), m^2/Pa
  std::vector<double> storage_diagonal_;
  double storage_diagonal_dt_ = -1.0;
};

}  // namespace seep::core
