// The supernodal factorization that replays CHOLMOD's arithmetic from a plan
// (core/src/flow/supernodal_refactorization.h) against CHOLMOD itself: on patterns of small
// supernodes, its own fixed-order kernels, within round-off of CHOLMOD and with bits that do not
// change with the BLAS's kernels; on large supernodes, CHOLMOD's BLAS calls and CHOLMOD's bits;
// new values each time, and the same failure on a matrix that is not positive definite.
#include "spd_factorization.h"

#include <cholmod.h>
#include <gtest/gtest.h>
#include <unistd.h>

#include <Eigen/CholmodSupport>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <random>
#include <string>
#include <vector>

#include "jittered_grid_system.h"
#include "supernodal_refactorization.h"

namespace seep::core::flow_internal {
namespace {

using flow_test::GridSystem;

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

// The answer of the plan's own kernels against CHOLMOD's: the same factorization in another
// order, so a difference of round-off. Both are backward stable; on these systems (condition
// numbers up to about 1e4, n <= 3,600) the differences seen are below 2e-15 of the largest
// entry, so 1e-12 leaves room and still catches a wrong row (an error of the size of an entry).
void ExpectRoundOffOf(const Eigen::VectorXd& x, const Eigen::VectorXd& expected) {
  ASSERT_EQ(x.size(), expected.size());
  EXPECT_LE((x - expected).cwiseAbs().maxCoeff(), 1e-12 * expected.cwiseAbs().maxCoeff());
}

// FNV-1a of the bytes of x: its bits in one number.
std::uint64_t BitsHash(const Eigen::VectorXd& x) {
  std::uint64_t h = 1469598103934665603ull;
  const auto* bytes = reinterpret_cast<const unsigned char*>(x.data());
  for (std::size_t i = 0; i < sizeof(double) * static_cast<std::size_t>(x.size()); ++i) {
    h = (h ^ bytes[i]) * 1099511628211ull;
  }
  return h;
}

// Three factorizations (CHOLMOD's first, two replays) and two solves of the side-60 system: the
// hash of every answer's bits.
std::uint64_t Side60AnswersHash() {
  const SparseMatrix first = GridSystem(60, 1);
  SpdFactorization factorization(LinearSolverKind::kCholmodSupernodal);
  EXPECT_TRUE(factorization.Analyze(first).ok());
  std::uint64_t h = 0;
  for (std::uint64_t seed = 1; seed < 4; ++seed) {
    const SparseMatrix values = seed == 1 ? first : NewValues(first, seed);
    EXPECT_TRUE(factorization.Factorize(values).ok());
    EXPECT_TRUE(factorization.own_kernels());
    Eigen::VectorXd x;
    EXPECT_TRUE(factorization.Solve(Rhs(values.rows(), seed), x).ok());
    h = h * 31 + BitsHash(x);
  }
  return h;
}

// Side 12: a handful of small supernodes. Side 60: 3,600 unknowns, supernodes of up to about a
// hundred rows. Side 160: 25,600 unknowns, a largest supernode of 275 rows. These three are
// factorized with the plan's own kernels. Side 280: 78,400 unknowns, a supernode of 473 rows,
// more than kOwnKernelMaxRows: CHOLMOD's loops run on threads and the BLAS calls are large enough
// to use OpenBLAS's blocked kernels, and the replay has CHOLMOD's own arithmetic and bits.
class ReplayedFactorization : public ::testing::TestWithParam<int> {};

TEST_P(ReplayedFactorization, GivesCholmodsAnswerForNewValues) {
  const int side = GetParam();
  const bool own_kernels = side <= 160;
  const SparseMatrix first = GridSystem(side, 1);
  SpdFactorization factorization(LinearSolverKind::kCholmodSupernodal);
  ASSERT_TRUE(factorization.Analyze(first).ok());
  ASSERT_TRUE(factorization.Factorize(first).ok());  // CHOLMOD itself; the plan is made here
  EXPECT_EQ(factorization.replayed_factorizations(), 0);
  for (std::uint64_t seed = 2; seed < 5; ++seed) {
    const SparseMatrix next = NewValues(first, seed);
    ASSERT_TRUE(factorization.Factorize(next).ok());
    ASSERT_EQ(factorization.replayed_factorizations(), static_cast<std::int64_t>(seed) - 1);
    ASSERT_EQ(factorization.own_kernels(), own_kernels) << "side " << side;
    for (std::uint64_t rhs_seed = 0; rhs_seed < 2; ++rhs_seed) {
      const Eigen::VectorXd b = Rhs(next.rows(), 100 * seed + rhs_seed);
      Eigen::VectorXd x;
      ASSERT_TRUE(factorization.Solve(b, x).ok());
      const Eigen::VectorXd expected = CholmodSolve(next, b);
      if (own_kernels) {
        ExpectRoundOffOf(x, expected);
      } else {
        EXPECT_TRUE(SameBits(x, expected))
            << "side " << side << ", values " << seed << ": largest difference "
            << (x - expected).cwiseAbs().maxCoeff() << " against |x| " << expected.norm();
      }
      // And the answer solves the system (the bits compared are those of a real solution).
      const Eigen::VectorXd residual = next.selfadjointView<Eigen::Lower>() * x - b;
      EXPECT_LT(residual.norm(), 1e-9 * b.norm());
    }
  }
}

INSTANTIATE_TEST_SUITE_P(Sides, ReplayedFactorization, ::testing::Values(12, 60, 160, 280));

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
  ExpectRoundOffOf(x, CholmodSolve(next, b));
}

// The plan's solve written the plain way, one column after another: y = P b; forward, each
// supernode's columns in order, each pushing its rows down (y(r) minus L(r, k) y(k)); backward,
// the supernodes and their columns in reverse, each a dot product with the rows below, in
// ascending row order, then divided by the diagonal; x = P' y. The order of every element's
// operations is the one SupernodalRefactorization::Solve documents.
Eigen::VectorXd OneColumnAtATimeSolve(const cholmod_factor& L, const Eigen::VectorXd& b) {
  const auto n = static_cast<int>(L.n);
  const auto* lx = static_cast<const double*>(L.x);
  const auto* super = static_cast<const int*>(L.super);
  const auto* lpi = static_cast<const int*>(L.pi);
  const auto* lpx = static_cast<const int*>(L.px);
  const auto* ls = static_cast<const int*>(L.s);
  const auto* perm = static_cast<const int*>(L.Perm);
  std::vector<double> y(static_cast<std::size_t>(n));
  for (int k = 0; k < n; ++k) y[k] = b[perm ? perm[k] : k];
  const auto nsuper = static_cast<int>(L.nsuper);
  for (int s = 0; s < nsuper; ++s) {
    const int nsrow = lpi[s + 1] - lpi[s];
    for (int j = 0; j < super[s + 1] - super[s]; ++j) {
      const double* lj = lx + lpx[s] + static_cast<std::ptrdiff_t>(nsrow) * j;
      const int k = super[s] + j;
      y[k] /= lj[j];
      for (int i = j + 1; i < nsrow; ++i) y[ls[lpi[s] + i]] -= lj[i] * y[k];
    }
  }
  for (int s = nsuper - 1; s >= 0; --s) {
    const int nsrow = lpi[s + 1] - lpi[s];
    for (int j = super[s + 1] - super[s] - 1; j >= 0; --j) {
      const double* lj = lx + lpx[s] + static_cast<std::ptrdiff_t>(nsrow) * j;
      const int k = super[s] + j;
      double t = y[k];
      for (int i = j + 1; i < nsrow; ++i) t -= lj[i] * y[ls[lpi[s] + i]];
      y[k] = t / lj[j];
    }
  }
  Eigen::VectorXd x(n);
  for (int k = 0; k < n; ++k) x[perm ? perm[k] : k] = y[k];
  return x;
}

// The plan's solve runs the back substitution's column chains of independent supernodes side by
// side; its bits are those of the plain loop above, on factors from a handful of supernodes (side
// 12) to thousands with a largest of 275 rows (side 160), and its answer solves the system.
TEST(ReplayedFactorization, SolveGivesTheBitsOfOneColumnAtATime) {
  cholmod_common common;
  cholmod_start(&common);
  common.supernodal = CHOLMOD_SUPERNODAL;
  common.final_ll = 1;
  for (const int side : {12, 33, 60, 160}) {
    SCOPED_TRACE("side " + std::to_string(side));
    const SparseMatrix lower = GridSystem(side, 1);
    cholmod_sparse a = Eigen::viewAsCholmod(lower.selfadjointView<Eigen::Lower>());
    cholmod_factor* factor = cholmod_analyze(&a, &common);
    ASSERT_NE(factor, nullptr);
    ASSERT_TRUE(cholmod_factorize(&a, factor, &common));
    auto plan = SupernodalRefactorization::Plan(*factor, lower);
    ASSERT_TRUE(plan.has_value());
    ASSERT_TRUE(plan->OwnKernels());
    const SparseMatrix next = NewValues(lower, 5);
    ASSERT_TRUE(plan->Refactorize(next, *factor));
    for (std::uint64_t seed = 0; seed < 3; ++seed) {
      const Eigen::VectorXd b = Rhs(next.rows(), seed);
      Eigen::VectorXd x;
      ASSERT_TRUE(plan->Solve(*factor, b, x));
      const Eigen::VectorXd plain = OneColumnAtATimeSolve(*factor, b);
      EXPECT_TRUE(SameBits(x, plain)) << "largest difference " << (x - plain).cwiseAbs().maxCoeff();
      const Eigen::VectorXd residual = next.selfadjointView<Eigen::Lower>() * x - b;
      EXPECT_LT(residual.norm(), 1e-9 * b.norm());
    }
    cholmod_free_factor(&factor, &common);
  }
  cholmod_finish(&common);
}

// The point of the own kernels: the same bits whatever kernels the BLAS picked for the CPU. The
// same test binary, run again with OpenBLAS made to use its Nehalem kernels (this machine's are
// Haswell's or newer), prints the hash of its answers' bits; it must be this run's. (On the BLAS
// path the Terzaghi examples' hashes change under this setting.)
TEST(ReplayedFactorization, OwnKernelsGiveTheSameBitsWhateverKernelsTheBlasPicks) {
  if (std::getenv("SEEP_PRINT_SIDE60_HASH") != nullptr) {
    std::printf("side60-hash %llu\n", static_cast<unsigned long long>(Side60AnswersHash()));
    return;
  }
  char self[4096] = {};
  const ssize_t length = readlink("/proc/self/exe", self, sizeof(self) - 1);
  ASSERT_GT(length, 0);
  const std::string command =
      std::string("OPENBLAS_CORETYPE=Nehalem OPENBLAS_VERBOSE=2 SEEP_PRINT_SIDE60_HASH=1 '") +
      self +
      "' --gtest_filter=ReplayedFactorization.OwnKernelsGiveTheSameBitsWhateverKernelsTheBlasPicks"
      " 2>&1";
  FILE* child = popen(command.c_str(), "r");
  ASSERT_NE(child, nullptr);
  std::string output;
  char buffer[512];
  while (std::fgets(buffer, sizeof(buffer), child) != nullptr) output += buffer;
  ASSERT_EQ(pclose(child), 0) << output;
  // OpenBLAS says which kernels it took: without the other ones the comparison would show nothing.
  ASSERT_NE(output.find("Core: Nehalem"), std::string::npos)
      << "the child did not run on OpenBLAS's Nehalem kernels:\n"
      << output;
  const std::size_t at = output.find("side60-hash ");
  ASSERT_NE(at, std::string::npos) << output;
  const unsigned long long theirs = std::stoull(output.substr(at + 12));
  EXPECT_EQ(theirs, Side60AnswersHash()) << output;
}

}  // namespace
}  // namespace seep::core::flow_internal
