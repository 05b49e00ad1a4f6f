// ExplicitSolver: the PFC-style forward update (seed eq. 4, docs/physics.md §1.2),
//
//   P_i += (K_f / V_s,i) (dt (sum_j C_ij (P_j - P_i - o_ij) + Q_src,i) - dV_i)   non-fixed i,
//
// with o_ij the head offset of the pipe when the fluid has weight (pipe_head.h), 0 otherwise;
//
// guarded by a governor on the critical step (time_step_limit.h): the step is refused
// (FailedPrecondition naming the limiting domain and what to change), reduced to the limit, or,
// for experiments only, run with a flag in the report. It never runs above the limit silently.
//
// dt_crit is recomputed whenever the network's topology or coefficient stamp changed (conductances,
// volumes, roles); between such changes it is the same number, so it is cached.
//
// Hot path: one pass over pipes in storage order (q = C (P_b - P_a), scatter-add into a per-domain
// inflow accumulator) and one pass over domains (update, reset the accumulator). With diagnostics
// off and no dV that moves 16 B per pipe + 40 B per domain (about 36-40 B per pipe on a 2D
// packing). Number domains and pipes for locality (e.g. row-major): random numbering is 4-8x
// slower at 1e6 pipes (docs/performance.md §1.2).
//
// Threads (from kMinParallelItems domains): each thread's contiguous share of the domains passes
// over the pipes touching it in pipe order and adds to its own domains only, then updates them;
// every domain gets the same terms in the same order as on one thread, so the pressures are the
// same bits on any thread count. The budget's sums (diagnostics) keep the one-pass order: each
// share continues the previous share's sums, in turn (a parallel sum would round differently).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/flow_step_report.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/flow/fluid_tally.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/status.h"

namespace seep::core {

struct FlowAdvanceReport {
  std::int64_t sub_steps = 0;
  double sub_step = 0.0;  // s
  double dt_crit = 0.0;   // s
  std::int32_t limiting_domain = -1;
  double max_mass_balance_error = 0.0;  // over the sub-steps; NaN without diagnostics
  FlowStepReport last;                  // the final sub-step's report
};

enum class StepLimitPolicy {
  kRefuse,      // dt > safety * dt_crit -> FailedPrecondition, the network is left untouched.
  kReduce,      // the step taken is min(dt, safety * dt_crit); the report says which.
  kAdviseOnly,  // run as asked and set report.limit_exceeded (tests and experiments only).
};

struct ExplicitSolverOptions {
  double bulk_modulus = 2e9;  // K_f, Pa.
  StorageModel storage;
  double safety_factor = 0.9;  // in (0, 1]: the governor allows safety * dt_crit.
  StepLimitPolicy policy = StepLimitPolicy::kRefuse;
  // Validates the dV input and fills the budget part of the report. Costs about 30% of a step;
  // switch off only in tight loops that check the budget some other way.
  bool diagnostics = true;
};

class ExplicitSolver {
 public:
  static Result<ExplicitSolver> Create(const ExplicitSolverOptions& options);

  // Advances the network by one step of (at most) dt seconds. volume_change holds dV_i over the
  // step (m^2, per domain, empty = rigid). Fixed-pressure domains keep their pressure. With a
  // tally (diagnostics on, node_outflow_m2 sized to the network), the step's fluid is added to it.
  Result<FlowStepReport> Step(FlowNetwork& network, double dt,
                              std::span<const double> volume_change = {},
                              FluidTally* tally = nullptr);

  // Fluid sub-cycling (docs/physics.md §4.4 item 2): advances by exactly `duration` seconds in
  // n = ceil(duration / (safety * dt_crit)) equal steps, spreading volume_change (dV over the whole
  // duration, per domain, empty = rigid) evenly over them. Conductances and volumes are held fixed.
  // The policy does not apply: every sub-step is within the limit by construction.
  Result<FlowAdvanceReport> Advance(FlowNetwork& network, double duration,
                                    std::span<const double> volume_change = {},
                                    FluidTally* tally = nullptr);

  // The current limit (refreshes the cache from the network's stamps).
  Result<CriticalTimeStep> CriticalStep(const FlowNetwork& network);

  const ExplicitSolverOptions& options() const { return options_; }

 private:
  explicit ExplicitSolver(const ExplicitSolverOptions& options) : options_(options) {}
  Status Prepare(const FlowNetwork& network);
  // Capacities, rates, the critical step and the sources from the current values (checking the
  // values they read); allocates only when the network grew.
  void IndexPipesByShare(const FlowNetwork& network, int threads);
  Status RefreshCoefficients(const FlowNetwork& network);

  ExplicitSolverOptions options_;
  std::uint64_t topology_stamp_ = 0;
  std::uint64_t coefficient_stamp_ = 0;
  CriticalTimeStep limit_;
  std::vector<double> rate_;      // K_f / V_s (0 for fixed), 1/(Pa s) per m^2.
  std::vector<double> capacity_;  // V_s / K_f (0 for fixed), m^2/Pa.
  std::vector<double> sum_c_;     // sum of the pipe conductances per domain, m^2/(Pa s).
  // Per share of a refresh: its least dt_i (a member, so that a refresh allocates nothing).
  std::vector<CriticalTimeStep> share_limit_;
  // Per thread share of the domains (contiguous blocks, CSR): the pipes touching it, ascending,
  // and each one's two ends as the share adds to them: the domain when it is the share's, else
  // the share's sink slot past the domains (sum_c_ and inflow_ have one per share, never read).
  // Built for owner_threads_ threads on the topology of topology_stamp_ (0: not built).
  int owner_threads_ = 0;
  std::vector<std::int32_t> owner_start_;
  std::vector<std::int32_t> owner_pipes_;
  std::vector<std::int32_t> owner_end_a_;
  std::vector<std::int32_t> owner_end_b_;
  std::vector<double> gain_;  // dt K_f / V_s for gain_dt_.
  double gain_dt_ = -1.0;
  std::vector<double> inflow_;  // accumulator: sum q + Q_src, reset after each step.
  std::vector<double> stored_;  // per domain: V_s dP / K_f of the step (the threads' budget)
  // With fluid weight: the head inflow plus Q_src per domain, what inflow_ restarts from; empty
  // without (inflow_ restarts from the sources).
  std::vector<double> base_inflow_;
  std::vector<std::int32_t> sources_;
  std::vector<double> sub_step_volume_change_;
  bool warned_advise_only_ = false;  // log the advise-only overrun once, not every step
};

}  // namespace seep::core
