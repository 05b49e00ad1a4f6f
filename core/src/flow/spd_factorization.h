// Internal: one sparse SPD factorization behind a small interface, so the solvers choose CHOLMOD
// or Eigen's SimplicialLDLT at run time (or by size, kAuto) without templates leaking into public
// headers. Matrices are passed as their lower triangle (column-major, compressed).
#pragma once

#include <Eigen/Core>
#include <Eigen/SparseCore>
#include <cstdint>
#include <memory>

#include "seep/core/flow/linear_solver_kind.h"
#include "seep/core/status.h"

namespace seep::core::flow_internal {

using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

class SpdFactorization {
 public:
  explicit SpdFactorization(LinearSolverKind kind);
  ~SpdFactorization();
  SpdFactorization(SpdFactorization&&) noexcept;
  SpdFactorization& operator=(SpdFactorization&&) noexcept;

  // Symbolic analysis (ordering, elimination tree): once per sparsity pattern.
  Status Analyze(const SparseMatrix& lower);
  // Numeric factorization: whenever the values change. Needs a prior Analyze on the same pattern.
  Status Factorize(const SparseMatrix& lower);
  Status Solve(const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const;

  // Factorizations done by replaying CHOLMOD's arithmetic from a plan of the pattern
  // (supernodal_refactorization.h) rather than by CHOLMOD itself.
  std::int64_t replayed_factorizations() const { return replayed_factorizations_; }
  // Whether the current factor was made, and is solved, with the plan's own fixed-order kernels
  // rather than the BLAS (supernodal_refactorization.h): bits that do not depend on the machine.
  bool own_kernels() const;

  LinearSolverKind kind() const { return kind_; }
  // The factorization in use since the last Analyze (kind() itself unless that is kAuto).
  LinearSolverKind active_kind() const { return active_kind_; }

 private:
  struct Impl;
  LinearSolverKind kind_;
  LinearSolverKind active_kind_;
  std::unique_ptr<Impl> impl_;
  std::int64_t replayed_factorizations_ = 0;
};

}  // namespace seep::core::flow_internal
