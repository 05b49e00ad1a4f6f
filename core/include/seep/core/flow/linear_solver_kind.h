// Which sparse Cholesky factorises the SPD pressure systems of the implicit and steady solvers.
#pragma once

#include <cstdint>
#include <string_view>

namespace seep::core {

enum class LinearSolverKind {
  // Eigen's SimplicialLDLT below kSupernodalMinUnknowns unknowns, CHOLMOD supernodal from there
  // on (a scene asks for it with solver.linear_solver AUTO; its default is kCholmodSupernodal),
  // chosen at each symbolic analysis (a function of the system, so of the scene:
  // runs stay deterministic). Below the switch CHOLMOD's supernodal numeric factorization costs
  // 5-10x a simplicial one: it opens OpenMP regions and allocates per supernode, and a small
  // network has hundreds of tiny supernodes (400 unknowns: 345 us against 32 us; 1e4: 10.1 ms
  // against 5.8 ms; they meet near 4e4 on 2 cores; bench/flow prints both).
  kAuto,
  // CHOLMOD supernodal LL^T through Eigen's CholmodSupport (AMD/METIS ordering). The fastest on
  // large 2D networks (bench/flow); deterministic for a fixed BLAS and thread count.
  kCholmodSupernodal,
  // Eigen::SimplicialLDLT with AMD ordering: no external library; fine below ~1e5 unknowns.
  kEigenSimplicialLdlt,
};

// Where kAuto switches to CHOLMOD supernodal: below the crossing measured on 2 cores, since more
// cores (threaded BLAS in the supernodes) favour the supernodal side.
inline constexpr std::int64_t kSupernodalMinUnknowns = 20000;

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
