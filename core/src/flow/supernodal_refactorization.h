// Internal: CHOLMOD's supernodal numeric factorization replayed from a plan, bit for bit.
//
// Why: a coupled implicit scene factorizes its pressure system at every flow update with the
// same pattern. CHOLMOD 3.0.14 (Debian 12) opens an OpenMP region per supernode step (zeroing,
// mapping, copying, assembling, each with an `if` that is false on small supernodes), and
// libgomp ends even a region of one thread with a futex wake-up system call. On a small system
// those calls are most of the factorization (the Terzaghi column: 1.6 ms a step against 26 us
// of mechanics on a 2-core VM). The plan replays the very arithmetic of
// Supernodal/t_cholmod_super_numeric.c, in its order, with the same BLAS and LAPACK calls on the
// same arrays, and leaves out only the bookkeeping: the linked lists of pending descendants and
// the relative maps are the same at every factorization of a pattern, so they are worked out
// once. The factor it writes is CHOLMOD's own (L->x), so CHOLMOD's solve uses it unchanged.
//
// A pattern whose supernodes all have at most kOwnKernelMaxRows rows (every implicit coupled
// scene of the examples) is factorized and solved with kernels of its own instead of the BLAS
// (OwnKernels): the same arithmetic in one fixed order, so that the bits do not depend on the
// BLAS the machine has (OpenBLAS chooses its kernels per CPU, and they round differently), and
// without a BLAS call's fixed cost, which is most of a small supernode's. Larger patterns keep
// OpenBLAS's blocked kernels (a known limitation: docs/architecture.md §5.3).
#pragma once

#include <Eigen/SparseCore>
#include <optional>
#include <vector>

struct cholmod_factor_struct;

namespace seep::core::flow_internal {

class SupernodalRefactorization {
 public:
  using SparseMatrix = Eigen::SparseMatrix<double, Eigen::ColMajor, int>;

  // The plan for factor `L` (supernodal LL', int indices, real, as CHOLMOD left it after a
  // factorization of `lower`'s pattern). nullopt if `L` is of another kind. It takes the own
  // kernels when no supernode has more than `own_kernel_max_rows` rows (the solvers use
  // kOwnKernelMaxRows; bench/flow/refactorization_bench sets it to compare the two paths).
  static std::optional<SupernodalRefactorization> Plan(const cholmod_factor_struct& L,
                                                       const SparseMatrix& lower,
                                                       int own_kernel_max_rows = kOwnKernelMaxRows);

  // Factorizes `lower` (the planned pattern, new values) into L->x. False if the matrix is not
  // positive definite, or not of the planned size; L->x is then undefined and the caller lets
  // CHOLMOD factorize it (which reports a failure and its column the way CHOLMOD does).
  bool Refactorize(const SparseMatrix& lower, cholmod_factor_struct& L);

  // Whether the plan factorizes with its own kernels (see above); only then is Solve available.
  bool OwnKernels() const { return own_kernels_; }

  // x = A^-1 rhs with the factor L that Refactorize wrote, with the same fixed-order arithmetic
  // (permuted forward and back substitution over the supernodes). False when the plan does not
  // use its own kernels, or for another size.
  bool Solve(const cholmod_factor_struct& L, const Eigen::VectorXd& rhs, Eigen::VectorXd& x) const;

  // The largest supernode (rows) of a pattern factorized with the plan's own kernels: up to it the
  // loops beat the BLAS calls; beyond, OpenBLAS's blocking wins (the steady solve of 1e6 unknowns
  // has supernodes of thousands of rows). seep_refactorization_bench (jittered grids, session
  // 25), the BLAS path's refactorization time over the own kernels' with one BLAS thread and with
  // OpenBLAS's default two: largest supernode 275 rows 1.19x and 1.31x, 362 rows 1.09x and
  // 1.11-1.13x, 428 rows 1.02x and 1.03x, 473 rows 0.90x and 0.87-0.94x.
  static constexpr int kOwnKernelMaxRows = 384;

 private:
  struct Supernode {
    int psx;    // first entry of the supernode in L->x
    int nsrow;  // rows (leading dimension)
    int nscol;  // columns
    int updates_end;
  };
  // One pending descendant d updating supernode s (CHOLMOD's C = L1 * [L1; L2]').
  struct Update {
    int pdx1;    // first entry of d's rows that touch s, in L->x
    int ndrow;   // d's rows (leading dimension)
    int ndcol;   // d's columns
    int ndrow1;  // d's rows inside s's columns
    int ndrow2;  // d's rows from there to the end
    int map_begin;
  };

  std::vector<Supernode> supernodes_;
  std::vector<Update> updates_;
  std::vector<int> relative_map_;  // per update: ndrow2 rows of s
  std::vector<int> value_slot_;    // per stored entry of `lower`: its place in L->x, or -1
  std::vector<double> update_;     // CHOLMOD's C (L->maxcsize)
  std::size_t factor_size_ = 0;    // entries of L->x the supernodes use

  // CHOLMOD's C of one descendant into c (the own kernels or the BLAS).
  void DescendantProducts(const Update& u, const double* lx, double* c) const;
  // C's entries subtracted from the supernode's columns through the relative map.
  void ScatterUpdate(const Update& u, const Supernode& s, const double* c, double* lx) const;
  // The supernode's columns factorized in place (the own kernels, or dpotrf and dtrsm); false if
  // a pivot is not positive.
  bool FactorSupernode(const Supernode& s, double* lx) const;

  // Groups the supernodes for Solve's back substitution (back_order_, back_group_); `parent` is
  // each supernode's parent in the supernodal tree, -1 for a root.
  void ScheduleBackSubstitution(const std::vector<int>& parent);

  bool own_kernels_ = false;
  mutable std::vector<double> work_;  // Solve's permuted right-hand side, solved in place
  // The back substitution's order: groups of up to kBackGroup supernodes none of which is
  // another's ancestor, each group after the groups of its members' parents; back_group_[g] ..
  // back_group_[g + 1] index back_order_. A column's chain of subtractions waits on each one
  // before it, and on its supernode's later columns; the chains of a group's supernodes do not
  // wait on each other, so Solve runs them side by side (see Solve).
  static constexpr int kBackGroup = 4;
  std::vector<int> back_order_;
  std::vector<int> back_group_;
};

}  // namespace seep::core::flow_internal
