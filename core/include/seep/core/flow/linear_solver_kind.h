// Which sparse Cholesky factorises the SPD pressure systems of the implicit and steady solvers.
#pragma once

#include <cstdint>
#include <string_view>

namespace seep::core {

enum class LinearSolverKind {
  // CHOLMOD supernodal LL^T through Eigen's CholmodSupport (AMD/METIS ordering). The fastest on
  // large 2D networks (bench/flow); deterministic for a fixed BLAS and thread count.
  kCholmodSupernodal,
  // Eigen::SimplicialLDLT with AMD ordering: no external library; fine below ~1e5 unknowns.
  kEigenSimplicialLdlt,
};

std::string_view LinearSolverKindName(LinearSolverKind kind);

// How often a solver re-did each stage: lets callers (and tests) see the reuse of the symbolic
// analysis (per topology) and of the numeric factorization (per conductances, volumes and dt).
struct LinearSystemStats {
  std::int64_t analyses = 0;
  std::int64_t factorizations = 0;
  std::int64_t solves = 0;
};

}  // namespace seep::core
