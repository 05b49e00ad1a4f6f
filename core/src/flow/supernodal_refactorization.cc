#include "supernodal_refactorization.h"

#include <cholmod.h>

#include <algorithm>
#include <cmath>

// The Fortran BLAS and LAPACK entry points CHOLMOD itself calls (cholmod_blas.h: 32-bit
// integers, no hidden string lengths). Declared here, not taken from a C interface, so that the
// very same routines run on the very same arguments.
extern "C" {
void dsyrk_(const char* uplo, const char* trans, const int* n, const int* k, const double* alpha,
            const double* a, const int* lda, const double* beta, double* c, const int* ldc);
void dgemm_(const char* transa, const char* transb, const int* m, const int* n, const int* k,
            const double* alpha, const double* a, const int* lda, const double* b, const int* ldb,
            const double* beta, double* c, const int* ldc);
void dpotrf_(const char* uplo, const int* n, double* a, const int* lda, int* info);
void dtrsm_(const char* side, const char* uplo, const char* transa, const char* diag, const int* m,
            const int* n, const double* alpha, const double* a, const int* lda, double* b,
            const int* ldb);
}

namespace seep::core::flow_internal {
namespace {

// The kernels of a plan small enough for them (OwnKernels): every element summed in one order,
// with no fused multiply-add (-ffp-contract=off), so that the factor's bits are the same on any
// x86-64 machine for a given build. OpenBLAS picks its kernels for the CPU it runs on, and they
// round differently (the Terzaghi examples ended with other hashes under OPENBLAS_CORETYPE
// Sandybridge, Nehalem or SkylakeX than on this machine's Haswell kernels): a job resumed on a
// worker with another CPU went on with other bits. On small supernodes these loops are also
// cheaper than a BLAS call, whose entry and buffer lock cost more than its arithmetic.

// Both kernels keep each element's running sum in registers over the whole k loop, a block of
// rows at a time (8, then 4, 2 and 1 for what is left; vectorised across the rows): the same
// operations in the same order per element as a loop that stores after every k, so the same
// bits, without a load and a store of every element for every k, and with a block's chains
// interleaved where a lone chain would wait on each add.

// acc[b] += x(i + b, k) * x(j, k) for k = 0 .. ncol - 1 in turn (kSign -1: -= instead).
template <int kWidth, int kSign>
inline void AccumulateRows(const double* x, int ldx, int ncol, int i, int j, double* acc) {
  for (int k = 0; k < ncol; ++k) {
    const double* xk = x + static_cast<std::ptrdiff_t>(ldx) * k;
    const double xjk = xk[j];
    for (int b = 0; b < kWidth; ++b) {
      if constexpr (kSign > 0) {
        acc[b] += xk[i + b] * xjk;
      } else {
        acc[b] -= xk[i + b] * xjk;
      }
    }
  }
}

// Calls block.template operator()<width>(i) over the rows [i, end) in blocks of 8, then one each
// of 4, 2 and 1 as the rows left allow; stops at the first block that returns false.
template <typename Block>
inline bool ForRowBlocks(int i, int end, const Block& block) {
  for (; end - i >= 8; i += 8) {
    if (!block.template operator()<8>(i)) return false;
  }
  if (end - i >= 4) {
    if (!block.template operator()<4>(i)) return false;
    i += 4;
  }
  if (end - i >= 2) {
    if (!block.template operator()<2>(i)) return false;
    i += 2;
  }
  return end - i < 1 || block.template operator()<1>(i);
}

// CHOLMOD's C = L1 [L1; L2]' of one descendant: c(i, j) = sum_k d(i, k) d(j, k) for the
// columns j < n1 and the rows i in [j, n2), with k ascending from 0 (dsyrk and dgemm of the BLAS
// path).
void OwnDescendantProducts(const double* d, int ldd, int n1, int n2, int ncol, double* c, int ldc) {
  for (int j = 0; j < n1; ++j) {
    double* cj = c + static_cast<std::ptrdiff_t>(ldc) * j;
    ForRowBlocks(j, n2, [&]<int kWidth>(int i) {
      double acc[kWidth] = {};
      AccumulateRows<kWidth, 1>(d, ldd, ncol, i, j, acc);
      std::copy(acc, acc + kWidth, cj + i);
      return true;
    });
  }
}

// The supernode's columns in place: the Cholesky factor of its diagonal block and the rows below
// divided by its transpose (dpotrf and dtrsm of the BLAS path), left-looking, column by column:
// a(i, j) minus a(i, k) a(j, k) for k ascending, then the diagonal's square root, then the rows
// below divided by it. False if a pivot is not positive (or not a number).
bool OwnFactorColumns(double* a, int nsrow, int nscol) {
  for (int j = 0; j < nscol; ++j) {
    double* aj = a + static_cast<std::ptrdiff_t>(nsrow) * j;
    double pivot = 0.0;
    const bool factored = ForRowBlocks(j, nsrow, [&]<int kWidth>(int i) {
      double acc[kWidth];
      for (int b = 0; b < kWidth; ++b) acc[b] = aj[i + b];
      AccumulateRows<kWidth, -1>(a, nsrow, j, i, j, acc);
      int b = 0;
      if (i == j) {  // the first block holds the diagonal, whose root divides every row below
        if (!(acc[0] > 0.0)) return false;
        pivot = std::sqrt(acc[0]);
        aj[j] = pivot;
        b = 1;
      }
      for (; b < kWidth; ++b) aj[i + b] = acc[b] / pivot;
      return true;
    });
    if (!factored) return false;
  }
  return true;
}

}  // namespace

std::optional<SupernodalRefactorization> SupernodalRefactorization::Plan(const cholmod_factor& L,
                                                                         const SparseMatrix& lower,
                                                                         int own_kernel_max_rows) {
  if (!L.is_super || !L.is_ll || L.itype != CHOLMOD_INT || L.xtype != CHOLMOD_REAL ||
      L.dtype != CHOLMOD_DOUBLE || L.x == nullptr || !lower.isCompressed() ||
      lower.rows() != static_cast<Eigen::Index>(L.n) || lower.cols() != lower.rows()) {
    return std::nullopt;
  }
  const int n = static_cast<int>(L.n);
  const int nsuper = static_cast<int>(L.nsuper);
  const int* super = static_cast<const int*>(L.super);
  const int* lpi = static_cast<const int*>(L.pi);
  const int* lpx = static_cast<const int*>(L.px);
  const int* ls = static_cast<const int*>(L.s);
  const int* perm = static_cast<const int*>(L.Perm);

  SupernodalRefactorization plan;
  plan.factor_size_ = static_cast<std::size_t>(lpx[nsuper]);
  plan.own_kernels_ = true;
  for (int s = 0; s < nsuper; ++s) {
    if (lpi[s + 1] - lpi[s] > own_kernel_max_rows) plan.own_kernels_ = false;
  }
  if (plan.own_kernels_) plan.work_.resize(static_cast<std::size_t>(n));
  plan.update_.resize(std::max<std::size_t>(L.maxcsize, 1));

  std::vector<int> inverse_perm(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) inverse_perm[perm ? perm[k] : k] = k;
  std::vector<int> super_of_column(static_cast<std::size_t>(n));
  for (int s = 0; s < nsuper; ++s) {
    for (int k = super[s]; k < super[s + 1]; ++k) super_of_column[k] = s;
  }

  // The stored entries of the lower triangle by their column of the permuted matrix (what
  // cholmod_factorize hands the numeric step: tril(A(p,p)), an exact copy of the values).
  std::vector<int> column_start(static_cast<std::size_t>(n) + 1, 0);
  const int* outer = lower.outerIndexPtr();
  const int* inner = lower.innerIndexPtr();
  for (int c = 0; c < n; ++c) {
    for (int e = outer[c]; e < outer[c + 1]; ++e) {
      if (inner[e] < c) continue;  // above the diagonal: CHOLMOD ignores it (stype < 0)
      ++column_start[std::min(inverse_perm[inner[e]], inverse_perm[c]) + 1];
    }
  }
  for (int k = 0; k < n; ++k) column_start[k + 1] += column_start[k];
  std::vector<int> entry_row(static_cast<std::size_t>(column_start[n]));
  std::vector<int> entry_index(entry_row.size());
  {
    std::vector<int> fill(column_start.begin(), column_start.end() - 1);
    for (int c = 0; c < n; ++c) {
      for (int e = outer[c]; e < outer[c + 1]; ++e) {
        if (inner[e] < c) continue;
        const int pr = inverse_perm[inner[e]];
        const int pc = inverse_perm[c];
        const int slot = fill[std::min(pr, pc)]++;
        entry_row[slot] = std::max(pr, pc);
        entry_index[slot] = e;
      }
    }
  }
  plan.value_slot_.assign(static_cast<std::size_t>(lower.nonZeros()), -1);

  // CHOLMOD's left-looking schedule, walked once without arithmetic: each supernode s is
  // updated by the pending descendants in its linked list (Head/Next, last placed first), and
  // each descendant then moves on to the list of the next supernode its rows reach.
  std::vector<int> head(static_cast<std::size_t>(nsuper), -1);
  std::vector<int> next(static_cast<std::size_t>(nsuper), -1);
  std::vector<int> lpos(static_cast<std::size_t>(nsuper), 0);
  std::vector<int> row_in_super(static_cast<std::size_t>(n), -1);  // CHOLMOD's Map
  plan.supernodes_.reserve(static_cast<std::size_t>(nsuper));
  std::vector<int> parent(static_cast<std::size_t>(nsuper), -1);
  for (int s = 0; s < nsuper; ++s) {
    const int k1 = super[s];
    const int k2 = super[s + 1];
    const int nscol = k2 - k1;
    const int psi = lpi[s];
    const int psx = lpx[s];
    const int nsrow = lpi[s + 1] - psi;
    for (int k = 0; k < nsrow; ++k) row_in_super[ls[psi + k]] = k;
    for (int k = k1; k < k2; ++k) {
      for (int slot = column_start[k]; slot < column_start[k + 1]; ++slot) {
        const int row = row_in_super[entry_row[slot]];
        if (row < 0 || row >= nsrow || ls[psi + row] != entry_row[slot]) return std::nullopt;
        plan.value_slot_[entry_index[slot]] = psx + (k - k1) * nsrow + row;
      }
    }
    for (int d = head[s]; d != -1;) {
      const int pdi = lpi[d];
      const int pdend = lpi[d + 1];
      const int ndrow = pdend - pdi;
      const int pdi1 = pdi + lpos[d];
      int pdi2 = pdi1;
      while (pdi2 < pdend && ls[pdi2] < k2) ++pdi2;
      const Update update{.pdx1 = lpx[d] + lpos[d],
                          .ndrow = ndrow,
                          .ndcol = super[d + 1] - super[d],
                          .ndrow1 = pdi2 - pdi1,
                          .ndrow2 = pdend - pdi1,
                          .map_begin = static_cast<int>(plan.relative_map_.size())};
      if (update.ndrow1 <= 0) return std::nullopt;
      for (int i = 0; i < update.ndrow2; ++i) {
        plan.relative_map_.push_back(row_in_super[ls[pdi1 + i]]);
      }
      plan.updates_.push_back(update);
      const int dnext = next[d];
      lpos[d] = pdi2 - pdi;
      if (lpos[d] < ndrow) {
        const int ancestor = super_of_column[ls[pdi2]];
        next[d] = head[ancestor];
        head[ancestor] = d;
      }
      d = dnext;
    }
    if (nsrow > nscol) {
      lpos[s] = nscol;
      parent[s] = super_of_column[ls[psi + nscol]];
      if (parent[s] <= s) return std::nullopt;  // not CHOLMOD's order: its own factorization
      next[s] = head[parent[s]];
      head[parent[s]] = s;
    }
    head[s] = -1;
    plan.supernodes_.push_back({.psx = psx,
                                .nsrow = nsrow,
                                .nscol = nscol,
                                .updates_end = static_cast<int>(plan.updates_.size())});
  }
  if (plan.own_kernels_) plan.ScheduleBackSubstitution(parent);
  return plan;
}

void SupernodalRefactorization::ScheduleBackSubstitution(const std::vector<int>& parent) {
  const auto nsuper = static_cast<int>(supernodes_.size());
  // Each supernode's chain length (its columns' terms) and, below it in the tree, the longest
  // path of such lengths: a group takes the ready supernodes with the longest paths first.
  std::vector<std::int64_t> path(static_cast<std::size_t>(nsuper), 0);
  std::vector<std::vector<int>> children(static_cast<std::size_t>(nsuper));
  for (int s = 0; s < nsuper; ++s) {  // children before parents (supernodes are postordered)
    const Supernode& sn = supernodes_[s];
    for (int j = 0; j < sn.nscol; ++j) path[s] += sn.nsrow - j;
    if (parent[s] >= 0) {
      path[parent[s]] = std::max(path[parent[s]], path[s]);
      children[parent[s]].push_back(s);
    }
  }
  const auto before = [&](int a, int b) { return path[a] != path[b] ? path[a] > path[b] : a > b; };
  std::vector<int> ready;
  for (int s = 0; s < nsuper; ++s) {
    if (parent[s] < 0) ready.push_back(s);
  }
  back_order_.clear();
  back_group_.assign(1, 0);
  while (!ready.empty()) {
    std::sort(ready.begin(), ready.end(), before);
    const auto take = std::min<std::ptrdiff_t>(std::ssize(ready), kBackGroup);
    back_order_.insert(back_order_.end(), ready.begin(), ready.begin() + take);
    ready.erase(ready.begin(), ready.begin() + take);
    for (auto s = back_order_.end() - take; s != back_order_.end(); ++s) {
      ready.insert(ready.end(), children[*s].begin(), children[*s].end());
    }
    back_group_.push_back(static_cast<int>(back_order_.size()));
  }
}

namespace {

// kCount independent chains of the back substitution side by side, each over its next `terms`
// terms: t[c] minus l[c][i] y[rows[c][i]] for i ascending, the same operations in the same order
// as one chain after another.
template <int kCount>
inline void RunChains(const double* const* l, const int* const* rows, int terms, const double* y,
                      double* t) {
  for (int i = 0; i < terms; ++i) {
    for (int c = 0; c < kCount; ++c) t[c] -= l[c][i] * y[rows[c][i]];
  }
}

}  // namespace

bool SupernodalRefactorization::Refactorize(const SparseMatrix& lower, cholmod_factor& L) {
  // Not the planned pattern (a caller's contract broken): CHOLMOD itself, which plans again.
  const auto nonzeros = static_cast<std::ptrdiff_t>(value_slot_.size());
  if (lower.nonZeros() != nonzeros || lower.rows() != static_cast<Eigen::Index>(L.n) ||
      !lower.isCompressed()) {
    return false;
  }
  double* lx = static_cast<double*>(L.x);
  std::fill(lx, lx + factor_size_, 0.0);
  const double* values = lower.valuePtr();
  for (std::ptrdiff_t e = 0; e < nonzeros; ++e) {
    if (value_slot_[e] >= 0) lx[value_slot_[e]] = values[e];
  }
  double* c = update_.data();
  int update = 0;
  for (const Supernode& s : supernodes_) {
    for (; update < s.updates_end; ++update) {
      const Update& u = updates_[update];
      DescendantProducts(u, lx, c);
      ScatterUpdate(u, s, c, lx);
    }
    if (!FactorSupernode(s, lx)) return false;
  }
  L.minor = L.n;
  return true;
}

void SupernodalRefactorization::DescendantProducts(const Update& u, const double* lx,
                                                   double* c) const {
  if (own_kernels_) {
    OwnDescendantProducts(lx + u.pdx1, u.ndrow, u.ndrow1, u.ndrow2, u.ndcol, c, u.ndrow2);
    return;
  }
  static constexpr double kOne = 1.0;
  static constexpr double kZero = 0.0;
  dsyrk_("L", "N", &u.ndrow1, &u.ndcol, &kOne, lx + u.pdx1, &u.ndrow, &kZero, c, &u.ndrow2);
  const int ndrow3 = u.ndrow2 - u.ndrow1;
  if (ndrow3 > 0) {
    dgemm_("N", "C", &ndrow3, &u.ndrow1, &u.ndcol, &kOne, lx + u.pdx1 + u.ndrow1, &u.ndrow,
           lx + u.pdx1, &u.ndrow, &kZero, c + u.ndrow1, &u.ndrow2);
  }
}

bool SupernodalRefactorization::FactorSupernode(const Supernode& s, double* lx) const {
  if (own_kernels_) return OwnFactorColumns(lx + s.psx, s.nsrow, s.nscol);
  int info = 1;
  dpotrf_("L", &s.nscol, lx + s.psx, &s.nsrow, &info);
  if (info != 0) return false;
  const int nsrow2 = s.nsrow - s.nscol;
  if (nsrow2 > 0) {
    static constexpr double kOne = 1.0;
    dtrsm_("R", "L", "C", "N", &nsrow2, &s.nscol, &kOne, lx + s.psx, &s.nsrow, lx + s.psx + s.nscol,
           &s.nsrow);
  }
  return true;
}

void SupernodalRefactorization::ScatterUpdate(const Update& u, const Supernode& s, const double* c,
                                              double* lx) const {
  const int* map = relative_map_.data() + u.map_begin;
  for (int j = 0; j < u.ndrow1; ++j) {
    double* column = lx + s.psx + map[j] * s.nsrow;
    const double* cj = c + static_cast<std::ptrdiff_t>(u.ndrow2) * j;
    for (int i = j; i < u.ndrow2; ++i) column[map[i]] -= cj[i];
  }
}

bool SupernodalRefactorization::Solve(const cholmod_factor& L, const Eigen::VectorXd& rhs,
                                      Eigen::VectorXd& x) const {
  const auto n = static_cast<int>(L.n);
  if (!own_kernels_ || rhs.size() != n || work_.size() != L.n) return false;
  // L's own arrays (Plan checked their kind): the supernodes' first columns, their rows, the
  // permutation (none: the identity).
  const double* lx = static_cast<const double*>(L.x);
  const int* super = static_cast<const int*>(L.super);
  const int* lpi = static_cast<const int*>(L.pi);
  const int* ls = static_cast<const int*>(L.s);
  const int* perm = static_cast<const int*>(L.Perm);
  double* y = work_.data();
  for (int k = 0; k < n; ++k) y[k] = rhs[perm ? perm[k] : k];  // y = P b
  const auto nsuper = static_cast<int>(supernodes_.size());
  // L y' = y: each supernode's columns in turn, each column's rows below pushed down: y(r) minus
  // L(r, k1 + j) y(k1 + j) for the supernodes in order and their columns j ascending. Within a
  // supernode, its own rows (the first nscol, which are k1, k1 + 1, ...) column by column; the
  // rows below it a block at a time, each row's terms over the columns summed in a register.
  for (int s = 0; s < nsuper; ++s) {
    const Supernode& sn = supernodes_[s];
    const int k1 = super[s];
    const int* rows = ls + lpi[s];
    const double* ls_x = lx + sn.psx;
    for (int j = 0; j < sn.nscol; ++j) {
      const double* lj = ls_x + static_cast<std::ptrdiff_t>(sn.nsrow) * j;
      const double yj = y[k1 + j] / lj[j];
      y[k1 + j] = yj;
      for (int i = j + 1; i < sn.nscol; ++i) y[k1 + i] -= lj[i] * yj;
    }
    const double* ys = y + k1;
    ForRowBlocks(sn.nscol, sn.nsrow, [&]<int kWidth>(int i) {
      double acc[kWidth];
      for (int b = 0; b < kWidth; ++b) acc[b] = y[rows[i + b]];
      for (int j = 0; j < sn.nscol; ++j) {
        const double* lj = ls_x + static_cast<std::ptrdiff_t>(sn.nsrow) * j;
        for (int b = 0; b < kWidth; ++b) acc[b] -= lj[i + b] * ys[j];
      }
      for (int b = 0; b < kWidth; ++b) y[rows[i + b]] = acc[b];
      return true;
    });
  }
  // L' z = y': each supernode's columns backwards, each column's dot product with the rows below:
  // y(k1 + j) minus L(r, k1 + j) y(r) for its rows r below the diagonal in turn, then divided by
  // the diagonal. A column's chain waits on each subtraction, and its first terms on the
  // supernode's later columns, but not on another supernode of its group (none is an ancestor of
  // another, and their ancestors are done): the group's current columns run side by side, their
  // common length of terms at a time, each in its own order, so the bits are the one-by-one
  // loop's.
  for (std::size_t g = 0; g + 1 < back_group_.size(); ++g) {
    int column[kBackGroup];  // each member's current column, from its last down to 0
    const int* members = back_order_.data() + back_group_[g];
    const int count = back_group_[g + 1] - back_group_[g];
    for (int m = 0; m < count; ++m) column[m] = supernodes_[members[m]].nscol - 1;
    while (true) {
      // One chain per member with a column left: where it stands, its terms left, its sum, and
      // its column's diagonal and place in y.
      const double* l[kBackGroup];
      const int* rows[kBackGroup];
      int left[kBackGroup];
      double t[kBackGroup];
      const double* diagonal[kBackGroup];
      int target[kBackGroup];
      int chains = 0;
      for (int m = 0; m < count; ++m) {
        const int j = column[m]--;
        if (j < 0) continue;
        const int s = members[m];
        const Supernode& sn = supernodes_[s];
        const double* lj = lx + sn.psx + static_cast<std::ptrdiff_t>(sn.nsrow) * j;
        l[chains] = lj + j + 1;
        rows[chains] = ls + lpi[s] + j + 1;
        left[chains] = sn.nsrow - j - 1;
        t[chains] = y[super[s] + j];
        diagonal[chains] = lj + j;
        target[chains] = super[s] + j;
        ++chains;
      }
      if (chains == 0) break;
      // The chains [0, active) together while all have terms left; a finished one is swapped
      // behind them, so the others go on as a smaller group.
      for (int active = chains; active > 0;) {
        int terms = left[0];
        for (int c = 1; c < active; ++c) terms = std::min(terms, left[c]);
        static_assert(kBackGroup == 4, "one case per group size");
        switch (active) {
          case 1:
            RunChains<1>(l, rows, terms, y, t);
            break;
          case 2:
            RunChains<2>(l, rows, terms, y, t);
            break;
          case 3:
            RunChains<3>(l, rows, terms, y, t);
            break;
          default:
            RunChains<4>(l, rows, terms, y, t);
            break;
        }
        for (int c = active - 1; c >= 0; --c) {
          l[c] += terms;
          rows[c] += terms;
          left[c] -= terms;
          if (left[c] > 0) continue;
          --active;
          std::swap(l[c], l[active]);
          std::swap(rows[c], rows[active]);
          std::swap(left[c], left[active]);
          std::swap(t[c], t[active]);
          std::swap(diagonal[c], diagonal[active]);
          std::swap(target[c], target[active]);
        }
      }
      for (int c = 0; c < chains; ++c) y[target[c]] = t[c] / *diagonal[c];
    }
  }
  x.resize(n);
  for (int k = 0; k < n; ++k) x[perm ? perm[k] : k] = y[k];  // x = P' z
  return true;
}

}  // namespace seep::core::flow_internal
