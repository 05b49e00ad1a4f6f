// The supernodal refactorization on its own kernels against the same plan on the BLAS
// (core/src/flow/supernodal_refactorization.h): where the own kernels stop being the faster, so
// that kOwnKernelMaxRows (the largest supernode that still takes them, and with them bits that
// do not depend on the machine's BLAS) is set from a measurement. Prints numbers; asserts
// nothing.
//
//   seep_refactorization_bench [sides 20,40,70,100,140,200,280] [repeats 15]
//
// Per side: a conductance Laplacian on a jittered side x side grid with one diagonal link in
// three cells (irregular supernodes) plus a storage diagonal, the pressure system's shape;
// CHOLMOD's supernodal analysis and first factorization; then, best of `repeats`, one
// refactorization and one solve with the plan on its own kernels and on the BLAS, the largest
// supernode's rows, and the ratio BLAS / own (above 1: the own kernels are faster).
#include <cholmod.h>

#include <Eigen/CholmodSupport>
#include <Eigen/SparseCore>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <vector>

#include "jittered_grid_system.h"
#include "supernodal_refactorization.h"

namespace {

using seep::core::flow_internal::SupernodalRefactorization;
using SparseMatrix = SupernodalRefactorization::SparseMatrix;
using Clock = std::chrono::steady_clock;
using seep::core::flow_test::GridSystem;

template <typename F>
double BestSeconds(int repeats, F&& f) {
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const auto t0 = Clock::now();
    f();
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return best;
}

std::vector<int> ParseSides(const char* text) {
  std::vector<int> sides;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) sides.push_back(std::atoi(item.c_str()));
  return sides;
}

}  // namespace

int main(int argc, char** argv) {
  const std::vector<int> sides = ParseSides(argc > 1 ? argv[1] : "20,40,70,100,140,200,280");
  const int repeats = argc > 2 ? std::atoi(argv[2]) : 15;
  if (repeats < 1) {
    std::fprintf(stderr, "repeats: must be a whole number of at least 1 (got '%s')\n", argv[2]);
    return 1;
  }
  cholmod_common common;
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.final_ll = 1;
  std::printf(
      "seep_refactorization_bench: best of %d, one thread of ours (CHOLMOD's first "
      "factorization aside)\n",
      repeats);
  std::printf("%8s %12s %9s | %12s %12s %7s | %11s %11s %7s\n", "unknowns", "factor nnz",
              "max rows", "refact. own", "refact. BLAS", "ratio", "solve own", "solve BLAS",
              "ratio");
  for (const int side : sides) {
    if (side < 2) {
      std::fprintf(stderr, "side %d: must be at least 2\n", side);
      return 1;
    }
    const SparseMatrix lower = GridSystem(side, 1);
    // CHOLMOD's symmetric matrix (stored lower triangle), without a copy.
    cholmod_sparse a = Eigen::viewAsCholmod(lower.selfadjointView<Eigen::Lower>());
    cholmod_factor* factor = cholmod_analyze(&a, &common);
    if (factor == nullptr || !cholmod_factorize(&a, factor, &common) || !factor->is_super) {
      std::fprintf(stderr, "side %d: CHOLMOD did not make a supernodal factor\n", side);
      return 1;
    }
    int max_rows = 0;
    const int* pi = static_cast<const int*>(factor->pi);
    for (std::size_t s = 0; s < factor->nsuper; ++s)
      max_rows = std::max(max_rows, pi[s + 1] - pi[s]);
    auto own = SupernodalRefactorization::Plan(*factor, lower, std::numeric_limits<int>::max());
    auto blas = SupernodalRefactorization::Plan(*factor, lower, 0);
    if (!own || !blas || !own->OwnKernels() || blas->OwnKernels()) {
      std::fprintf(stderr, "side %d: no plan\n", side);
      return 1;
    }
    // The same new values for both paths (what a coupled update hands the solver).
    const SparseMatrix next = GridSystem(side, 2);
    const double refactor_own = BestSeconds(repeats, [&] { own->Refactorize(next, *factor); });
    const double refactor_blas = BestSeconds(repeats, [&] { blas->Refactorize(next, *factor); });
    // The solves: the own one with the plan; the BLAS path's is CHOLMOD's cholmod_solve2 (dense
    // triangular solves through dtrsv/dgemv), on the factor the BLAS path just wrote.
    Eigen::VectorXd rhs = Eigen::VectorXd::Ones(lower.rows());
    Eigen::VectorXd x;
    own->Refactorize(next, *factor);
    const double solve_own = BestSeconds(repeats, [&] { own->Solve(*factor, rhs, x); });
    blas->Refactorize(next, *factor);
    cholmod_dense b = Eigen::viewAsCholmod(rhs);
    cholmod_dense* solution = nullptr;
    cholmod_dense* y = nullptr;
    cholmod_dense* e = nullptr;
    const double solve_blas = BestSeconds(repeats, [&] {
      cholmod_solve2(CHOLMOD_A, factor, &b, nullptr, &solution, nullptr, &y, &e, &common);
    });
    std::printf("%8lld %12zu %9d | %9.3f ms %9.3f ms %6.2fx | %8.3f ms %8.3f ms %6.2fx\n",
                static_cast<long long>(lower.rows()), static_cast<std::size_t>(factor->xsize),
                max_rows, 1e3 * refactor_own, 1e3 * refactor_blas, refactor_blas / refactor_own,
                1e3 * solve_own, 1e3 * solve_blas, solve_blas / solve_own);
    for (cholmod_dense** d : {&solution, &y, &e}) cholmod_free_dense(d, &common);
    cholmod_free_factor(&factor, &common);
  }
  cholmod_finish(&common);
  return 0;
}
