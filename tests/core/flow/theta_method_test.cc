// The theta option of ImplicitSolver (docs/physics.md §4.5): Crank–Nicolson (theta = 1/2) against
// the exact discrete solution of the 1D chain, its order in time next to backward Euler's on the 1D
// transient diffusion problem (docs/physics.md §3.2 case (a)), its fluid budget per step, and the
// validation of theta.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <vector>

#include "chain_reference.h"
#include "flow_test_networks.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/flow/time_step_limit.h"

namespace seep::core {
namespace {

using testing::LatticeParams;
using testing::TimeScheme;

constexpr int kN = 20;  // chain of 20 cells: nodes 0 (p = 1) .. 20 (p = 0), 19 unknowns

FlowNetwork PoreChain() {
  const LatticeParams lp;
  return testing::MakeChain(kN, lp, lp.SquareApparentVolume(), lp.SquarePoreVolume(), false);
}

ImplicitSolver MakeTheta(double theta) {
  ImplicitSolverOptions opt;
  opt.bulk_modulus = LatticeParams{}.bulk_modulus;
  opt.theta = theta;
  auto s = ImplicitSolver::Create(opt);
  EXPECT_TRUE(s.ok()) << s.status().ToString();
  return std::move(s).value();
}

double ChainDtCrit() {
  const FlowNetwork net = PoreChain();
  return ComputeCriticalTimeStep(net, LatticeParams{}.bulk_modulus, {})->dt_crit;
}

TEST(ThetaMethod, ThetaOutsideHalfToOneIsRefusedNamingTheField) {
  for (const double bad :
       {0.0, 0.49, 1.01, std::nan(""), std::numeric_limits<double>::infinity()}) {
    ImplicitSolverOptions opt;
    opt.theta = bad;
    const auto s = ImplicitSolver::Create(opt);
    ASSERT_FALSE(s.ok()) << bad;
    EXPECT_EQ(s.status().code(), StatusCode::kInvalidArgument);
    EXPECT_NE(s.status().message().find("flow.implicit.theta"), std::string::npos)
        << s.status().ToString();
  }
  for (const double good : {0.5, 0.75, 1.0}) {
    ImplicitSolverOptions opt;
    opt.theta = good;
    EXPECT_TRUE(ImplicitSolver::Create(opt).ok()) << good;
  }
}

// The theta method multiplies mode m by (1 - (1 - theta) lambda_m dt)/(1 + theta lambda_m dt) per
// step: the exact discrete solution (chain_reference.h); Crank–Nicolson at theta = 1/2. 1e-12 of
// p1: a solve per step at eps times the condition number of the chain (~ 1e3), summed over 50
// steps, with a 100x margin. At 10 dt_crit Crank–Nicolson's fast modes flip sign every step, so
// this also checks the non-monotone regime exactly.
TEST(ThetaMethod, MatchesExactDiscreteSolution) {
  const LatticeParams lp;
  for (const double theta : {0.5, 0.75}) {
    for (const double factor : {0.5, 10.0}) {
      FlowNetwork net = PoreChain();
      ImplicitSolver solver = MakeTheta(theta);
      const double dt = factor * ChainDtCrit();
      for (int step = 1; step <= 50; ++step) {
        ASSERT_TRUE(solver.Step(net, dt).ok());
        if (step % 10 != 0) continue;
        for (int i = 1; i < kN; ++i) {
          EXPECT_NEAR(net.pressure()[i],
                      testing::ChainDiscreteTheta(kN, i, step, dt, lp.bulk_modulus,
                                                  lp.Conductance(), lp.SquarePoreVolume(), theta),
                      1e-12)
              << "theta " << theta << ", " << factor << " dt_crit, node " << i << ", step " << step;
        }
      }
    }
  }
  // theta = 1/2 is the Crank–Nicolson reference of chain_reference.h.
  EXPECT_DOUBLE_EQ(
      testing::ChainDiscreteTheta(kN, 5, 7, 1e-3, 2e9, 1e-10, 1e-6, 0.5),
      testing::ChainDiscreteExact(kN, 5, 7, 1e-3, 2e9, 1e-10, 1e-6, TimeScheme::kCrankNicolson));
}

// Max over the interior nodes of |P - P_exact-in-time| at T = 0.2, P_exact-in-time being the
// chain's semi-discrete solution (e^{-lambda_m t} per mode): the spatial error is the same for
// every scheme and cancels, so what is left is the time-stepping error alone.
double TimeErrorAtT(double theta, double dt_over_crit, double T) {
  const LatticeParams lp;
  const double h = 2.0 * lp.radius;
  const double v = lp.SquarePoreVolume();
  const double c = lp.bulk_modulus * lp.Conductance() * h * h / v;  // docs/physics.md §3.2
  const double length = kN * h;
  const double t_end = T * length * length / c;
  const double dt = dt_over_crit * ChainDtCrit();
  const int steps = static_cast<int>(std::lround(t_end / dt));
  EXPECT_NEAR(steps * dt, t_end, 1e-9 * t_end) << "T must be a whole number of steps";
  FlowNetwork net = PoreChain();
  ImplicitSolver solver = MakeTheta(theta);
  for (int s = 0; s < steps; ++s) EXPECT_TRUE(solver.Step(net, dt).ok());
  double worst = 0.0;
  for (int i = 1; i < kN; ++i) {
    const double exact = testing::ChainDiscreteExact(kN, i, 1, t_end, lp.bulk_modulus,
                                                     lp.Conductance(), v, TimeScheme::kExact);
    worst = std::max(worst, std::abs(net.pressure()[i] - exact));
  }
  return worst;
}

// Observed order log2(e(dt)/e(dt/2)) on the 1D transient problem at T = 0.2 (docs/physics.md §3.2
// case (a)), dt = 4, 2, 1, 0.5 dt_crit (= 0.005 .. 0.000625 L^2/c; T = 0.2 is 40 .. 320 steps).
// Leading error terms: BE dt lambda^2 t/2 e^{-lambda t}, CN dt^2 lambda^3 t/12 e^{-lambda t}, with
// relative corrections O(lambda dt) ~ 0.05 for the slowest mode at 4 dt_crit. The orders must come
// out within 0.1 of 1 and of 2: that allows the O(lambda dt) correction (it moves an order by
// ~ log2(1 + 0.05) = 0.07 at the coarsest pair) but not a drop to the other scheme's order. At
// 4 dt_crit CN's fastest modes still flip sign (lambda_max dt = 8, factor -0.6 per step), but
// after 40 steps they are down by 0.6^40 ~ 1e-9: below the second-order error (~ 1e-5).
TEST(ThetaMethod, CrankNicolsonIsSecondOrderAndBackwardEulerFirstOrderInTime) {
  constexpr double kT = 0.2;
  const std::vector<double> factors{4.0, 2.0, 1.0, 0.5};
  for (const double theta : {1.0, 0.5}) {
    const double expected_order = theta == 1.0 ? 1.0 : 2.0;
    std::vector<double> errors;
    for (const double f : factors) errors.push_back(TimeErrorAtT(theta, f, kT));
    for (std::size_t k = 0; k + 1 < errors.size(); ++k) {
      const double order = std::log2(errors[k] / errors[k + 1]);
      std::printf("[ measured ] theta %.1f: error %.3e at %g dt_crit, %.3e at %g: order %.3f\n",
                  theta, errors[k], factors[k], errors[k + 1], factors[k + 1], order);
      EXPECT_NEAR(order, expected_order, 0.1) << "theta " << theta << " between " << factors[k]
                                              << " and " << factors[k + 1] << " dt_crit";
    }
  }
  // And at the same step CN is the more accurate by far (1 dt_crit: ~1e-6 against ~1e-3).
  EXPECT_LT(TimeErrorAtT(0.5, 1.0, kT), 0.01 * TimeErrorAtT(1.0, 1.0, kT));
}

// Fluid budget per step, measured here independently of the solver's report: the stored excess
// sum V_s P / K_f changes by dt (theta q_in(P^{n+1}) + (1 - theta) q_in(P^n)), q_in the net inflow
// from the two fixed ends (ComputeBoundaryFluxes). Relative to the fluid held plus the gross
// boundary throughput of the step, as in flow_step_report.h; 1e-12 is ~1e4 eps, the rounding of
// sums over 19 domains and 2 boundary pipes with a wide margin. The solver's own figure must agree.
TEST(ThetaMethod, CrankNicolsonConservesFluidPerStep) {
  const LatticeParams lp;
  for (const double factor : {0.5, 10.0, 1000.0}) {
    FlowNetwork net = PoreChain();
    ImplicitSolver solver = MakeTheta(0.5);
    const double dt = factor * ChainDtCrit();
    double worst = 0.0;
    double worst_reported = 0.0;
    for (int step = 1; step <= 100; ++step) {
      const double excess_before = StoredFluidExcess(net, lp.bulk_modulus, {}).value();
      const BoundaryFluxes before = ComputeBoundaryFluxes(net);
      const auto r = solver.Step(net, dt);
      ASSERT_TRUE(r.ok()) << r.status().ToString();
      const BoundaryFluxes after = ComputeBoundaryFluxes(net);
      const double in_before = before.total_inflow - before.total_outflow;
      const double in_after = after.total_inflow - after.total_outflow;
      const double moved = dt * (0.5 * in_after + 0.5 * in_before);
      const double stored = StoredFluidExcess(net, lp.bulk_modulus, {}).value() - excess_before;
      double held = 0.0;
      for (int i = 1; i < kN; ++i) held += std::abs(net.pressure()[i]);
      held *= lp.SquarePoreVolume() / lp.bulk_modulus;
      const double gross = dt * (before.total_inflow + before.total_outflow + after.total_inflow +
                                 after.total_outflow);
      worst = std::max(worst, std::abs(stored - moved) / (held + std::abs(stored) + gross));
      worst_reported = std::max(worst_reported, r->mass_balance_error);
      EXPECT_NEAR(r->boundary_inflow, 0.5 * (in_before + in_after),
                  1e-12 * (before.total_inflow + after.total_inflow));
    }
    EXPECT_LE(worst, 1e-12) << factor << " dt_crit";
    EXPECT_LE(worst_reported, 1e-12) << factor << " dt_crit";
    std::printf("[ measured ] CN %g dt_crit: worst budget error per step %.3e (reported %.3e)\n",
                factor, worst, worst_reported);
  }
}

}  // namespace
}  // namespace seep::core
