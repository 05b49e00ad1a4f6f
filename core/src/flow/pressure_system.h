// Internal: the SPD pressure system shared by the backward-Euler and steady solvers
// (docs/physics.md §4.5):
//
//   A = diag(s) + L_ff,   L_ff(i,i) = sum_j C_ij (all neighbours), L_ff(i,j) = -C_ij (free j),
//
// over the unknowns = domains that are neither fixed-pressure nor pinned. s is the storage
// diagonal V_s/(K_f dt) for backward Euler and 0 for the steady state. Known neighbours (fixed or
// pinned) go to the right-hand side.
//
// Caching: the unknown numbering, the lower-triangle pattern, the value slot of every pipe and the
// symbolic analysis are rebuilt only when the topology key changes; values are re-assembled and
// refactorised only when the value key changes (conductances, volumes, dt).
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "spd_factorization.h"

namespace seep::core::flow_internal {

class PressureSystem {
 public:
  explicit PressureSystem(LinearSolverKind kind) : factorization_(kind) {}

  // pinned[d] != 0 marks extra known domains held at pressure 0 (steady closed components); empty
  // for none. Must be a function of the topology (it is part of the topology key).
  Status SyncTopology(const FlowNetwork& network, std::span<const std::uint8_t> pinned);

  // storage_diagonal: per domain (ignored for known domains), empty for all zeros. value_key
  // identifies the values: re-assembly and refactorisation happen only when it changes.
  Status SyncValues(const FlowNetwork& network, std::span<const double> storage_diagonal,
                    std::uint64_t coefficient_stamp, double dt_key);

  // rhs[u] += sum over known neighbours j of C_uj P_j (pinned domains count as P = 0).
  void AddKnownCoupling(const FlowNetwork& network, Eigen::VectorXd& rhs) const;

  Status Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x);

  std::size_t num_unknowns() const { return domain_of_unknown_.size(); }
  std::span<const std::int32_t> unknown_of_domain() const { return unknown_of_domain_; }
  std::span<const std::int32_t> domain_of_unknown() const { return domain_of_unknown_; }
  bool is_pinned(std::size_t d) const { return !pinned_.empty() && pinned_[d] != 0; }
  const LinearSystemStats& stats() const { return stats_; }
  LinearSolverKind linear_solver_in_use() const { return factorization_.active_kind(); }

 private:
  SpdFactorization factorization_;
  SparseMatrix matrix_;                          // lower triangle
  std::vector<std::int32_t> unknown_of_domain_;  // -1 for known domains
  std::vector<std::int32_t> domain_of_unknown_;
  std::vector<std::uint8_t> pinned_;
  std::vector<int> diagonal_slot_;  // per unknown: index into matrix_ values
  std::vector<int> pipe_slot_a_;    // per pipe: diagonal slot of end a, -1 if known
  std::vector<int> pipe_slot_b_;    // per pipe: diagonal slot of end b, -1 if known
  std::vector<int> pipe_slot_off_;  // per pipe: off-diagonal slot, -1 unless both ends unknown
  std::uint64_t topology_key_ = 0;
  std::uint64_t coefficient_key_ = 0;
  double dt_key_ = -1.0;
  bool values_valid_ = false;
  LinearSystemStats stats_;
};

}  // namespace seep::core::flow_internal
