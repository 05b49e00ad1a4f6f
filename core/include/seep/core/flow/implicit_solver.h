// ImplicitSolver: the theta method on the pipe network (docs/physics.md §4.5): backward Euler
// (theta = 1, the default) or Crank–Nicolson (theta = 1/2). For every non-fixed domain i
//
//   (V_s,i/K_f)(P_i^{n+1} - P_i^n)/dt = theta F_i(P^{n+1}) + (1 - theta) F_i(P^n)
//                                       + Q_src,i - dV_i/dt,    F_i(P) = sum_j C_ij (P_j - P_i);
//
// fixed-pressure domains hold their current value at both time levels.
//
// Backward Euler is first order in time, unconditionally stable and monotone: its system matrix is
// an SPD M-matrix, so no new extrema appear at any dt. Crank–Nicolson is second order in time and
// unconditionally stable, but NOT monotone once dt/dt_crit exceeds about 1 (a mode of rate lambda
// is multiplied by (1 - lambda dt/2)/(1 + lambda dt/2), which tends to -1 for the fast modes):
// after a sharp change (a pressure step, a source switched on) the fast modes flip sign every
// step and decay slowly, so pressures overshoot the bounds of the data and oscillate near the
// disturbance. Use it for smooth transients where accuracy per step matters; use backward Euler
// for steps far above dt_crit, shocks and runs towards the steady state.
//
// Increment form. The solver solves for dP = P^{n+1} - P^n:
//
//   (S/(theta dt) + L_ff) dP = (F(P^n) + Q_src - dV/dt) / theta,   S = diag(V_s/K_f),
//
// whose right-hand side is the (small) imbalance of the current state rather than S P^n / dt:
// near equilibrium dP is small and so is its rounding, and no large terms cancel.
//
// Closed components. On a component with no fixed node L_ff is singular and only S/(theta dt)
// fixes its mean level: at dt = m dt_crit the matrix's condition number is about m, and the
// solve's rounding moves the component's stored fluid by about eps m of what it holds (4e-11 at
// m = 1e6, 3e-3 at 1e15). After the solve, dP of each connected component gets the constant
// shift that makes the component's fluid budget exact: the Galerkin correction of the solve on
// the component-constant vectors (one step of iterative refinement on the near-null space),
//
//   alpha_c = 1_c^T (b - A dP) / 1_c^T A 1_c,
//
// computed with every interior pipe left out (their fluxes cancel in the sum exactly, not to
// rounding). For an anchored component it is a rounding-level change; for a closed one it
// restores sum V_s P + the fluid moved in to rounding at any dt/dt_crit (physics-wise exact: a
// constant shift leaves every pipe flux unchanged and is precisely the direction the solve
// cannot resolve).
//
// Reuse: the symbolic analysis is redone only when the network's topology stamp changes, the
// numeric factorization only when its coefficient stamp or dt changes; otherwise a step is one
// right-hand side and one back-substitution. stats() counts each stage.
#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <memory>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/flow_step_report.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/flow/fluid_tally.h"
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
  // Time weighting of the pipe fluxes, in [0.5, 1]: 1 = backward Euler (first order, monotone),
  // 0.5 = Crank–Nicolson (second order, oscillates for dt >> dt_crit; see the file comment).
  double theta = 1.0;
};

class ImplicitSolver {
 public:
  static Result<ImplicitSolver> Create(const ImplicitSolverOptions& options);
  ~ImplicitSolver();
  ImplicitSolver(ImplicitSolver&&) noexcept;
  ImplicitSolver& operator=(ImplicitSolver&&) noexcept;

  // One theta-method step of dt seconds. volume_change: dV_i over the step (m^2), empty = rigid.
  // The report carries dt_crit of the explicit scheme for reference (dt / dt_crit = how much the
  // implicit step buys); its boundary_inflow is the flux the scheme transports over the step,
  // theta q(P^{n+1}) + (1 - theta) q(P^n). With a tally (diagnostics on, node_outflow_m2 sized
  // to the network), the step's fluid is added to it.
  Result<FlowStepReport> Step(FlowNetwork& network, double dt,
                              std::span<const double> volume_change = {},
                              FluidTally* tally = nullptr);

  // The factorization of the last symbolic analysis: options.linear_solver itself, or for kAuto
  // the one it chose for this network's size.
  LinearSolverKind linear_solver_in_use() const;
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
  // Per unknown: its connected component; per component: the sum of V_s/K_f (m^2/Pa).
  std::vector<std::int32_t> component_of_unknown_;
  std::size_t num_components_ = 0;
  std::vector<double> component_capacity_;
  // Pipes with exactly one unknown end (to a fixed node), in pipe order: what the per-component
  // budget sees of the outside.
  std::vector<std::int32_t> boundary_pipes_;
  std::vector<double> storage_diagonal_;
  double storage_diagonal_dt_ = -1.0;
  // Work arrays of Prepare and Step, kept so that a step allocates nothing.
  CriticalTimeStepScratch limit_scratch_;
  Eigen::VectorXd rhs_, increment_;             // b and the solution x = P^{n+1} - P^n per unknown
  std::vector<double> residual_, denominator_;  // per component
  std::vector<double> pore_growth_rate_;        // dV / dt per unknown (empty without dV)
};

}  // namespace seep::core
