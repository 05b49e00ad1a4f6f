// V10 explicit limit sharpness, V11 backward Euler at 100 dt_crit, V18 the dt formula
// (docs/physics.md §4.1, §5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "chain_reference.h"
#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/time_step_limit.h"

namespace seep::core {
namespace {

using testing::LatticeParams;

constexpr int kStabilityChainCells = 20;

// Max |P| seen while running the explicit scheme at `factor` x dt_crit up to T = 0.5.
double MaxAbsPressure(FlowNetwork net, double factor, double time_scale, StepLimitPolicy policy,
                      Status* status) {
  const LatticeParams lp;
  ExplicitSolverOptions opt;
  opt.bulk_modulus = lp.bulk_modulus;
  opt.safety_factor = 1.0;
  opt.policy = policy;
  auto solver = ExplicitSolver::Create(opt);
  EXPECT_TRUE(solver.ok());
  const double dt = factor * solver->CriticalStep(net)->dt_crit;
  double max_abs = 0.0;
  for (double t = 0.0; t < 0.5 * time_scale;) {
    const auto r = solver->Step(net, dt);
    if (!r.ok()) {
      *status = r.status();
      return max_abs;
    }
    t += r->dt;
    for (const double p : net.pressure()) max_abs = std::max(max_abs, std::abs(p));
  }
  *status = Status::Ok();
  return max_abs;
}

TEST(Verification, V10_ExplicitLimitIsSharpOnBipartiteNetworks) {
  const LatticeParams lp;
  const double h = 2.0 * lp.radius;
  const double v = lp.SquarePoreVolume();
  const double c = lp.bulk_modulus * lp.Conductance() * h * h / v;

  // The N = 20 chain and a 20 x 20 square lattice with a Dirichlet left column: both bipartite.
  FlowNetwork chain =
      testing::MakeChain(kStabilityChainCells, lp, lp.SquareApparentVolume(), v, false);
  FlowNetwork lattice = testing::MakeOrDie(testing::MakeSquareLatticeData(20, 20, lp));
  for (int j = 0; j < 20; ++j) ASSERT_TRUE(lattice.SetFixedPressure(j * 20, 1.0).ok());
  // Seeded random interior state in [0, 1]: a row-uniform start would hold no checkerboard
  // component across rows, and the lattice would behave as a chain with half the stiffness.
  std::mt19937_64 rng(5);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  for (std::size_t d = 0; d < lattice.num_domains(); ++d) {
    if (lattice.role()[d] == DomainRole::kFree) lattice.mutable_pressure()[d] = unit(rng);
  }
  const double time_scale =
      (kStabilityChainCells * h) * (kStabilityChainCells * h) / c;  // same length for both

  for (const FlowNetwork* net : {&chain, &lattice}) {
    Status status;
    const double bounded =
        MaxAbsPressure(*net, 0.99, time_scale, StepLimitPolicy::kAdviseOnly, &status);
    ASSERT_TRUE(status.ok());
    EXPECT_LE(bounded, 1.0 + 1e-12);  // maximum principle below the limit

    const double grown =
        MaxAbsPressure(*net, 1.05, time_scale, StepLimitPolicy::kAdviseOnly, &status);
    ASSERT_TRUE(status.ok());
    EXPECT_GT(grown, 1e3);  // the checkerboard mode grows by |1 - 1.05 lambda_max dt_crit|^n

    // Enforced: refused outright, or reduced to the limit and bounded.
    MaxAbsPressure(*net, 1.05, time_scale, StepLimitPolicy::kRefuse, &status);
    EXPECT_EQ(status.code(), StatusCode::kFailedPrecondition);
    EXPECT_NE(status.message().find("dt_crit"), std::string::npos);
    const double reduced =
        MaxAbsPressure(*net, 1.05, time_scale, StepLimitPolicy::kReduce, &status);
    ASSERT_TRUE(status.ok());
    EXPECT_LE(reduced, 1.0 + 1e-12);
  }
}

TEST(Verification, V11_BackwardEulerAtHundredTimesCriticalStep) {
  const LatticeParams lp;
  const double v = lp.SquarePoreVolume();
  FlowNetwork net =
      testing::MakeChain(kStabilityChainCells, lp, lp.SquareApparentVolume(), v, false);
  const auto limit = ComputeCriticalTimeStep(net, lp.bulk_modulus, {});
  ASSERT_TRUE(limit.ok());
  const double dt = 100.0 * limit->dt_crit;
  ImplicitSolverOptions opt;
  opt.bulk_modulus = lp.bulk_modulus;
  auto solver = ImplicitSolver::Create(opt);
  ASSERT_TRUE(solver.ok());
  std::vector<double> previous(net.pressure().begin(), net.pressure().end());
  for (int step = 1; step <= 80; ++step) {
    const auto r = solver->Step(net, dt);
    ASSERT_TRUE(r.ok());
    EXPECT_GE(r->min_pressure, 0.0);  // stable and positivity preserving
    EXPECT_LE(r->max_pressure, 1.0);
    for (int i = 1; i < kStabilityChainCells; ++i) {
      EXPECT_GE(net.pressure()[i], previous[i] - 1e-15) << "not monotone at node " << i;
      previous[i] = net.pressure()[i];
    }
    if (step == 5) {  // the transient is BE's own discrete solution (first order in time)
      for (int i = 1; i < kStabilityChainCells; ++i) {
        EXPECT_NEAR(
            net.pressure()[i],
            testing::ChainDiscreteExact(kStabilityChainCells, i, step, dt, lp.bulk_modulus,
                                        lp.Conductance(), v, testing::TimeScheme::kBackwardEuler),
            1e-10);
      }
    }
  }
  for (int i = 0; i <= kStabilityChainCells; ++i) {
    EXPECT_NEAR(net.pressure()[i], 1.0 - static_cast<double>(i) / kStabilityChainCells, 1e-10)
        << "node " << i;
  }
  // Same state as the steady solver.
  FlowNetwork steady =
      testing::MakeChain(kStabilityChainCells, lp, lp.SquareApparentVolume(), v, false);
  ASSERT_TRUE(SolveSteadyState(steady).ok());
  for (int i = 0; i <= kStabilityChainCells; ++i)
    EXPECT_NEAR(net.pressure()[i], steady.pressure()[i], 1e-10);
}

TEST(Verification, V18_CriticalStepFormula) {
  // Uniform lattices whose conductances the code computes from apertures: seed eq. 5,
  // dt = 24 mu R V / (N K_f a^3), equals the general form V / (K_f sum C) per domain.
  const LatticeParams lp;
  const double mu = lp.viscosity, r = lp.radius, kf = lp.bulk_modulus;
  for (const bool hex : {false, true}) {
    FlowNetworkData d =
        hex ? testing::MakeHoneycombData(9, 8, lp) : testing::MakeSquareLatticeData(8, 8, lp);
    FlowNetwork net = testing::MakeOrDie(d);
    const double a = 1.7e-5;
    ASSERT_TRUE(net.SetApertures(std::vector<double>(net.num_pipes(), a), mu).ok());
    for (const StorageVolume kind : {StorageVolume::kPore, StorageVolume::kApparent}) {
      const StorageModel storage{kind, 1.0};
      std::vector<double> per_domain(net.num_domains());
      const auto limit = ComputeCriticalTimeStep(net, kf, storage, per_domain);
      ASSERT_TRUE(limit.ok());
      const double vol = kind == StorageVolume::kPore
                             ? (hex ? lp.HexPoreVolume() : lp.SquarePoreVolume())
                             : (hex ? lp.HexApparentVolume() : lp.SquareApparentVolume());
      const int interior_pipes = hex ? 3 : 4;
      const double eq5 = 24.0 * mu * r * vol / (interior_pipes * kf * a * a * a);
      EXPECT_NEAR(limit->dt_crit, eq5, 1e-12 * eq5);
      // Every domain: N_i = its number of pipes.
      std::vector<int> pipes_of(net.num_domains(), 0);
      for (std::size_t p = 0; p < net.num_pipes(); ++p) {
        ++pipes_of[net.pipe_domain_a()[p]];
        ++pipes_of[net.pipe_domain_b()[p]];
      }
      for (std::size_t i = 0; i < net.num_domains(); ++i) {
        const double expected = 24.0 * mu * r * vol / (pipes_of[i] * kf * a * a * a);
        const double general = vol / (kf * pipes_of[i] * a * a * a / (12.0 * mu * 2.0 * r));
        EXPECT_NEAR(per_domain[i], expected, 1e-12 * expected);
        EXPECT_NEAR(per_domain[i], general, 1e-12 * general);
      }
    }
  }
  // Magnitude check against the reference table (docs/physics.md §4.2): R = 1 mm, k = 1e-12,
  // square, V_p: 1.07e-7 s; V_d: 5.0e-7 s (three significant figures).
  FlowNetwork sq = testing::MakeOrDie(testing::MakeSquareLatticeData(5, 5, lp));
  EXPECT_NEAR(ComputeCriticalTimeStep(sq, kf, {StorageVolume::kPore, 1.0})->dt_crit, 1.07e-7,
              0.005e-7);
  EXPECT_NEAR(ComputeCriticalTimeStep(sq, kf, {StorageVolume::kApparent, 1.0})->dt_crit, 5.0e-7,
              0.05e-7);
}

}  // namespace
}  // namespace seep::core
