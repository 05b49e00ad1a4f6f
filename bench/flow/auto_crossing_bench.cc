// Where solver.linear_solver AUTO should switch (kSupernodalMinUnknowns, linear_solver_kind.h):
// per system, what an implicit step pays for its pressure system through each concrete kind:
// one numeric factorization of new values and one solve, with the symbolic analysis done once
// (as a coupled run does: the pattern lives until the next detection). The CHOLMOD supernodal
// kind replays its factorization from a plan (supernodal_refactorization.h) from the second
// factorization on, which is what a run sees at every step but the first.
//
//   seep_auto_crossing_bench [repeats 15]
//
// Systems: the tests' jittered-grid pressure system on square grids (wide networks: fill grows
// like n log n) and on columns 12 unknowns wide (a consolidation column: narrow, little fill), from
// 100 to 90,000 unknowns. Prints, per system, the best time of each kind and the ratio
// simplicial / supernodal (above 1: the supernodal kind is the faster), and per shape at how many
// sizes from the current switch on each kind was the faster (a column's two kinds come within
// a shared machine's noise of each other at some sizes). Asserts nothing.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <string>
#include <vector>

#include "jittered_grid_system.h"
#include "spd_factorization.h"

namespace {

using seep::core::LinearSolverKind;
using seep::core::flow_internal::SparseMatrix;
using seep::core::flow_internal::SpdFactorization;
using seep::core::flow_test::GridSystem;
using Clock = std::chrono::steady_clock;

struct Shape {
  const char* name;
  int width;               // 0: square
  std::vector<int> sizes;  // side (square) or height (column)
};

// Best of `repeats` of one factorization and one solve with `kind`, after one analysis and two
// untimed factorizations (the first made by CHOLMOD, the second by the plan), alternating two
// value sets so that every timed factorization sees values other than the last.
double StepSeconds(LinearSolverKind kind, const SparseMatrix& a, const SparseMatrix& b,
                   int repeats) {
  SpdFactorization f(kind);
  const auto check = [](const seep::core::Status& status) {
    if (!status.ok()) {
      std::fprintf(stderr, "%s\n", status.message().c_str());
      std::exit(1);
    }
  };
  check(f.Analyze(a));
  check(f.Factorize(a));
  check(f.Factorize(b));
  const Eigen::VectorXd rhs = Eigen::VectorXd::Ones(a.rows());
  Eigen::VectorXd x;
  double best = std::numeric_limits<double>::infinity();
  for (int r = 0; r < repeats; ++r) {
    const SparseMatrix& values = r % 2 == 0 ? a : b;
    const auto t0 = Clock::now();
    check(f.Factorize(values));
    check(f.Solve(rhs, x));
    best = std::min(best, std::chrono::duration<double>(Clock::now() - t0).count());
  }
  return best;
}

}  // namespace

int main(int argc, char** argv) {
  const int repeats = argc > 1 ? std::atoi(argv[1]) : 15;
  if (repeats < 1) {
    std::fprintf(stderr, "repeats: must be a whole number of at least 1 (got '%s')\n", argv[1]);
    return 1;
  }
  const std::vector<Shape> shapes = {
      {"square", 0, {10, 14, 20, 28, 40, 56, 80, 110, 160, 220, 300}},
      {"column", 12, {8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096, 7500}},
  };
  std::printf("seep_auto_crossing_bench: best of %d, one factorization of new values + one solve\n",
              repeats);
  std::printf("%-7s %9s %9s | %14s %14s %8s\n", "shape", "grid", "unknowns", "simplicial LDLT",
              "supernodal", "ratio");
  for (const Shape& shape : shapes) {
    int faster = 0, slower = 0;  // sizes at or above the switch where the supernodal kind is so
    for (const int size : shape.sizes) {
      const int width = shape.width == 0 ? size : shape.width;
      const SparseMatrix a = GridSystem(width, size, 1);
      const SparseMatrix b = GridSystem(width, size, 2);
      const double ldlt = StepSeconds(LinearSolverKind::kEigenSimplicialLdlt, a, b, repeats);
      const double super = StepSeconds(LinearSolverKind::kCholmodSupernodal, a, b, repeats);
      const double ratio = ldlt / super;
      if (a.rows() >= seep::core::kSupernodalMinUnknowns) ++(ratio > 1.0 ? faster : slower);
      const std::string grid = std::to_string(width) + "x" + std::to_string(size);
      std::printf("%-7s %9s %9lld | %11.3f ms %11.3f ms %7.2fx\n", shape.name, grid.c_str(),
                  static_cast<long long>(a.rows()), 1e3 * ldlt, 1e3 * super, ratio);
    }
    std::printf(
        "%s: from AUTO's switch (%lld unknowns) on, supernodal the faster at %d of %d sizes\n",
        shape.name, static_cast<long long>(seep::core::kSupernodalMinUnknowns), faster,
        faster + slower);
  }
  return 0;
}
