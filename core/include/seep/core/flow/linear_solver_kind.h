// Which sparse Cholesky factorises the SPD pressure systems of the implicit and steady solvers.
#pragma once

#include <cstdint>
#include <string_view>

namespace seep::core {

enum class LinearSolverKind {
  // Eigen's SimplicialLDLT below kSupernodalMinUnknowns unknowns, CHOLMOD supernodal from there
  // on (a scene asks for it with solver.linear_solver AUTO; its default is kCholmodSupernodal),
  // chosen at each symbolic analysis (a function of the system, so of the scene: runs stay
  // deterministic). Tiny systems only: with the replayed refactorization
  // (supernodal_refactorization.h) the supernodal kind's step costs less than the simplicial
  // one's from about 200 unknowns (seep_auto_crossing_bench).
  kAuto,
  // CHOLMOD supernodal LL^T through Eigen's CholmodSupport (AMD/METIS ordering), refactorized by
  // replaying a plan of the pattern (supernodal_refactorization.h): the faster kind from about
  // 200 unknowns; its bits do not depend on the machine while its supernodes take the plan's own
  // kernels (up to about 40,000 unknowns), else on the BLAS.
  kCholmodSupernodal,
  // Eigen::SimplicialLDLT with AMD ordering: no external library; fine below ~1e5 unknowns.
  kEigenSimplicialLdlt,
};

// Where kAuto switches to CHOLMOD supernodal: the size from which seep_auto_crossing_bench (one
// refactorization of new values and one solve, one thread) finds the supernodal kind the faster;
// the figures are in docs/performance.md §3.
inline constexpr std::int64_t kSupernodalMinUnknowns = 200;

// The concrete kind a solver of that kind uses for a system of `unknowns` unknowns.
LinearSolverKind ResolvedLinearSolverKind(LinearSolverKind kind, std::int64_t unknowns);

std::string_view LinearSolverKindName(LinearSolverKind kind);

// How often a solver re-did each stage: lets callers (and tests) see the reuse of the symbolic
// analysis (per topology) and of the numeric factorization (per conductances, volumes and dt).
struct LinearSystemStats {
  std::int64_t analyses = 0;
  std::int64_t factorizations = 0;
  std::int64_t solves = 0;
};

}  // namespace seep::core
