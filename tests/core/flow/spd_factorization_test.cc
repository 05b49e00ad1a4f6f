// The supernodal factorization that replays CHOLMOD's arithmetic from a plan
// (core/src/flow/supernodal_refactorization.h) against CHOLMOD itself: the same bits, on
// patterns with small and large supernodes, with new values each time, and the same failure on
// a matrix that is not positive definite.
#include "spd_factorization.h"

#include <gtest/gtest.h>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <random>
#include <string>
#include <vector>

namespace seep::core::flow_internal {
namespace {

// The lower triangle of a pressure-like system: a conductance Laplacian on a jittered grid (with
// one diagonal link per cell, so that supernodes are irregular) plus a storage diagonal.
SparseMatrix GridSystem(int side, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> conductance(1e-3, 1.0);
  std::uniform_real_distribution<double> storage(1e-6, 1e-2);
  const int n = side * side;
  std::vector<Eigen::Triplet<double, int>> entries;
  std::vector<double> diagonal(static_cast<std::size_t>(n), 0.0);
  const auto link = [&](int a, int b) {
    const double c = conductance(rng);
    diagonal[a] += c;
    diagonal[b] += c;
    entries.emplace_back(std::max(a, b), std::min(a, b), -c);
  };
  for (int y = 0; y < side; ++y) {
    for (int x = 0; x < side; ++x) {
      const int u = y * side + x;
      if (x + 1 < side) link(u, u + 1);
      if (y + 1 < side) link(u, u + side);
      if (x + 1 < side && y + 1 < side && (x + y) % 3 == 0) link(u, u + side + 1);
    }
  }
  for (int u = 0; u < n; ++u) entries.emplace_back(u, u, diagonal[u] + storage(rng));
  SparseMatrix lower(n, n);
  lower.setFromTriplets(entries.begin(), entries.end());
  lower.makeCompressed();
  return lower;
}

// The same pattern with new values (what a coupled run hands the solver at every update).
SparseMatrix NewValues(const SparseMatrix& pattern, std::uint64_t seed) {
  SparseMatrix again = GridSystem(static_cast<int>(std::lround(std::sqrt(pattern.rows()))), seed);
  EXPECT_EQ(again.nonZeros(), pattern.nonZeros());
  return again;
}

Eigen::VectorXd Rhs(Eigen::Index n, std::uint64_t seed) {
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> value(-1.0, 1.0);
  Eigen::VectorXd b(n);
  for (Eigen::Index i = 0; i < n; ++i) b[i] = value(rng);
  return b;
}

// CHOLMOD's own answer: a fresh analysis and factorization of `lower`.
Eigen::VectorXd CholmodSolve(const SparseMatrix& lower, const Eigen::VectorXd& b) {
  Eigen::CholmodSupernodalLLT<SparseMatrix, Eigen::Lower> cholmod;
  cholmod.analyzePattern(lower);
  cholmod.factorize(lower);
  EXPECT_EQ(cholmod.info(), Eigen::Success);
  return cholmod.solve(b);
}

bool SameBits(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return a.size() == b.size() &&
         std::memcmp(a.data(), b.data(), sizeof(double) * static_cast<std::size_t>(a.size())) == 0;
}

// Side 12: a handful of small supernodes. Side 60: 3,600 unknowns. Side 160: 25,600 unknowns,
// supernodes of more than 64 rows and 1,024 entries, where CHOLMOD's loops run on threads and
// its BLAS calls are large enough to use OpenBLAS's blocked kernels.
class ReplayedFactorization : public ::testing::TestWithParam<int> {};

TEST_P(ReplayedFactorization, GivesCholmodsBitsForNewValues) {
  const int side = GetParam();
  const SparseMatrix first = GridSystem(side, 1);
  SpdFactorization factorization(LinearSolverKind::kCholmodSupernodal);
  ASSERT_TRUE(factorization.Analyze(first).ok());
  ASSERT_TRUE(factorization.Factorize(first).ok());  // CHOLMOD itself; the plan is made here
  EXPECT_EQ(factorization.replayed_factorizations(), 0);
  for (std::uint64_t seed = 2; seed < 5; ++seed) {
    const SparseMatrix next = NewValues(first, seed);
    ASSERT_TRUE(factorization.Factorize(next).ok());
    ASSERT_EQ(factorization.replayed_factorizations(), static_cast<std::int64_t>(seed) - 1);
    for (std::uint64_t rhs_seed = 0; rhs_seed < 2; ++rhs_seed) {
      const Eigen::VectorXd b = Rhs(next.rows(), 100 * seed + rhs_seed);
      Eigen::VectorXd x;
      ASSERT_TRUE(factorization.Solve(b, x).ok());
      const Eigen::VectorXd expected = CholmodSolve(next, b);
      EXPECT_TRUE(SameBits(x, expected))
          << "side " << side << ", values " << seed << ": largest difference "
          << (x - expected).cwiseAbs().maxCoeff() << " against |x| " << expected.norm();
      // And the answer solves the system (the bits compared are those of a real solution).
      const Eigen::VectorXd residual = next.selfadjointView<Eigen::Lower>() * x - b;
      EXPECT_LT(residual.norm(), 1e-9 * b.norm());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Sides, ReplayedFactorization, ::testing::Values(12, 60, 160));

TEST(ReplayedFactorization, NotPositiveDefiniteFailsAsCholmodDoesAndTheNextOneIsExactAgain) {
  const SparseMatrix first = GridSystem(30, 1);
  SpdFactorization factorization(LinearSolverKind::kCholmodSupernodal);
  ASSERT_TRUE(factorization.Analyze(first).ok());
  ASSERT_TRUE(factorization.Factorize(first).ok());

  SparseMatrix indefinite = NewValues(first, 7);
  indefinite.coeffRef(400, 400) = -1.0;
  const Status failed = factorization.Factorize(indefinite);
  EXPECT_EQ(failed.code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(failed.message().find("not positive definite"), std::string::npos) << failed.message();
  Eigen::VectorXd x;
  EXPECT_FALSE(factorization.Solve(Rhs(first.rows(), 1), x).ok());

  // The failed matrix went to CHOLMOD, and so does the next one (the plan is made again).
  EXPECT_EQ(factorization.replayed_factorizations(), 0);
  const SparseMatrix next = NewValues(first, 8);
  ASSERT_TRUE(factorization.Factorize(next).ok());
  ASSERT_TRUE(factorization.Factorize(next).ok());
  EXPECT_EQ(factorization.replayed_factorizations(), 1);
  const Eigen::VectorXd b = Rhs(next.rows(), 3);
  ASSERT_TRUE(factorization.Solve(b, x).ok());
  EXPECT_TRUE(SameBits(x, CholmodSolve(next, b)));
}

}  // namespace
}  // namespace seep::core::flow_internal
