// Internal: CHOLMOD's supernodal numeric factorization replayed from a plan, bit for bit.
//
// Why: a coupled implicit scene factorizes its pressure system at every flow update with the
// same pattern. CHOLMOD 3.0.14 (Debian 12) opens an OpenMP region per supernode step (zeroing,
// mapping, copying, assembling, each with an `if` that is false on small supernodes), and
// libgomp ends even a region of one thread with a futex wake-up system call. On a small system
// those calls are most of the factorization (the Terzaghi column: 1.6 ms a step against 26 us
// of mechanics on this VM). The plan replays the very arithmetic of
// Supernodal/t_cholmod_super_numeric.c, in its order, with the same BLAS and LAPACK calls on the
// same arrays, and leaves out only the bookkeeping: the linked lists of pending descendants and
// the relative maps are the same at every factorization of a pattern, so they are worked out
// once. The factor it writes is CHOLMOD's own (L->x), so CHOLMOD's solve uses it unchanged.
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
  // factorization of `lower`'s pattern). nullopt if `L` is of another kind.
  static std::optional<SupernodalRefactorization> Plan(const cholmod_factor_struct& L,
                                                       const SparseMatrix& lower);

  // Factorizes `lower` (the planned pattern, new values) into L->x. False if the matrix is not
  // positive definite, or not of the planned size; L->x is then undefined and the caller lets
  // CHOLMOD factorize it (which reports a failure and its column the way CHOLMOD does).
  bool Refactorize(const SparseMatrix& lower, cholmod_factor_struct& L);

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
};

}  // namespace seep::core::flow_internal
