// Extreme coefficients (docs/physics.md §4.3): a crack whose apertures exceed their neighbours' by
// 1e2 and by 1e6 (conductances by 1e6 and 1e18), and sliver domains whose storage volume is 1e-12
// of the others'. The explicit governor must take the tiny step or refuse naming the domain that
// forces it; backward Euler at the step of the unperturbed lattice must stay monotone and
// conservative and end on the steady state.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/time_step_limit.h"
#include "stability_invariants.h"
#include "stability_networks.h"

namespace seep::core {
namespace {

using stability::kWater;
constexpr double kContrastInlet = 1e5;  // Pa
constexpr int kContrastSide = 12;

testing::LatticeParams Params() {
  testing::LatticeParams lp;
  lp.bulk_modulus = kWater;
  return lp;
}

// 12 x 12 square-lattice permeameter, interior at 0. With `crack_ratio` > 1 the pipes along row 6
// (a horizontal crack from inlet to outlet) get that many times the aperture of their neighbours.
FlowNetwork Permeameter(double crack_ratio = 1.0) {
  const testing::LatticeParams lp = Params();
  FlowNetworkData d = testing::MakeSquareLatticeData(kContrastSide, kContrastSide, lp);
  for (std::size_t p = 0; p < d.pipe_aperture.size(); ++p) {
    const int a = d.pipe_domain_a[p];
    const int b = d.pipe_domain_b[p];
    if (a / kContrastSide == 6 && b == a + 1) {
      d.pipe_aperture[p] *= crack_ratio;
      const double ap = d.pipe_aperture[p];
      d.pipe_conductance[p] = ap * ap * ap / (12.0 * lp.viscosity * d.pipe_length[p]);
    }
  }
  stability::MakePermeameter(d, kContrastSide, kContrastSide, kContrastInlet, 0.0);
  return testing::MakeOrDie(std::move(d));
}

// Slivers: domain 40 keeps 1e-12 of its volume, its neighbour 41 1e-9, domain 90 1e-11.
constexpr std::int32_t kSliver = 40;
FlowNetwork SliverPermeameter() {
  FlowNetwork net = Permeameter();
  auto vp = net.mutable_pore_volume();
  auto va = net.mutable_apparent_volume();
  const std::vector<std::pair<std::int32_t, double>> factors = {
      {kSliver, 1e-12}, {41, 1e-9}, {90, 1e-11}};
  for (const auto& [d, f] : factors) {
    vp[d] *= f;
    va[d] *= f;
  }
  return net;
}

double UniformCriticalStep() { return ComputeCriticalTimeStep(Permeameter(), kWater, {})->dt_crit; }

ExplicitSolver MakeExplicit(StepLimitPolicy policy) {
  ExplicitSolverOptions opt;
  opt.bulk_modulus = kWater;
  opt.policy = policy;
  return ExplicitSolver::Create(opt).value();
}

// Explicit with kReduce asked for the unperturbed lattice's step: it must run at 0.9 x the real
// (tiny) limit, bounded and conservative.
void RunReducedExplicit(FlowNetwork net, int steps, const char* what) {
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  ExplicitSolver solver = MakeExplicit(StepLimitPolicy::kReduce);
  const double dt_crit = solver.CriticalStep(net)->dt_crit;
  stability::FluidLedger ledger(net, kWater, {});
  for (int step = 0; step < steps; ++step) {
    const auto r = ledger.Step(solver, net, UniformCriticalStep());
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_EQ(r->dt, 0.9 * dt_crit);
    ASSERT_TRUE(stability::AllFinite(net));
    ASSERT_TRUE(stability::WithinBounds(net, bounds)) << "step " << step;
  }
  EXPECT_TRUE(ledger.Conserved(net));
  EXPECT_TRUE(ledger.SolverReportWithin());
  stability::PrintMeasured(std::string(what) + " explicit cumulative mass error",
                           ledger.CumulativeError(net));
}

// Backward Euler at 100 x the unperturbed dt_crit from 0 up to the steady state: monotone at every
// domain, bounded, conservative, and equal to SteadyStateSolver's answer at the end.
void RunBackwardEulerToSteadyState(FlowNetwork net, const FlowNetwork& fresh, const char* what) {
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  ImplicitSolverOptions opt;
  opt.bulk_modulus = kWater;
  auto solver = ImplicitSolver::Create(opt);
  ASSERT_TRUE(solver.ok());
  const double dt = 100.0 * UniformCriticalStep();
  stability::FluidLedger ledger(net, kWater, {});
  std::vector<double> previous(net.pressure().begin(), net.pressure().end());
  for (int step = 0; step < 120; ++step) {
    const auto r = ledger.Step(*solver, net, dt);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_TRUE(stability::AllFinite(net));
    ASSERT_TRUE(stability::WithinBounds(net, bounds)) << "step " << step;
    for (std::size_t d = 0; d < net.num_domains(); ++d) {
      ASSERT_GE(net.pressure()[d], previous[d] - 1e-12 * kContrastInlet)
          << "not monotone at domain " << d << ", step " << step;
      previous[d] = net.pressure()[d];
    }
  }
  EXPECT_TRUE(ledger.Conserved(net));
  EXPECT_TRUE(ledger.SolverReportWithin());
  FlowNetwork steady = fresh;
  const auto sr = SolveSteadyState(steady);
  ASSERT_TRUE(sr.ok()) << sr.status().ToString();
  EXPECT_LE(sr->mass_balance_error, stability::kMassTolerance);
  EXPECT_TRUE(stability::WithinBounds(steady, bounds));
  double worst = 0.0;
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    worst = std::max(worst, std::abs(net.pressure()[d] - steady.pressure()[d]) / kContrastInlet);
  }
  EXPECT_LE(worst, 1e-10);
  stability::PrintMeasured(std::string(what) + " BE cumulative mass error",
                           ledger.CumulativeError(net));
  stability::PrintMeasured(std::string(what) + " BE distance to steady / p_in", worst);
  stability::PrintMeasured(std::string(what) + " steady mass balance", sr->mass_balance_error);
}

// The limit sits on the crack (row 6: every free domain there has two crack pipes; the lowest
// index wins the tie) and a step of the unperturbed lattice is refused naming that domain.
void ExpectCrackLimits(double ratio, double max_fraction_of_uniform) {
  FlowNetwork net = Permeameter(ratio);
  ExplicitSolver refusing = MakeExplicit(StepLimitPolicy::kRefuse);
  const auto limit = refusing.CriticalStep(net);
  ASSERT_TRUE(limit.ok());
  EXPECT_LT(limit->dt_crit, max_fraction_of_uniform * UniformCriticalStep());
  EXPECT_EQ(limit->limiting_domain / kContrastSide, 6);
  const auto refused = refusing.Step(net, 0.9 * UniformCriticalStep());
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(
      refused.status().message().find("at domain " + std::to_string(limit->limiting_domain) + ":"),
      std::string::npos)
      << refused.status().message();
}

TEST(Stability, CrackWithApertureContrastHundred) {
  ExpectCrackLimits(1e2, 1e-5);  // C x 1e6 on the crack
  RunReducedExplicit(Permeameter(1e2), 500, "crack 1e2");
  RunBackwardEulerToSteadyState(Permeameter(1e2), Permeameter(1e2), "crack 1e2");
}

TEST(Stability, CrackWithApertureContrastMillion) {
  ExpectCrackLimits(1e6, 1e-17);  // C x 1e18 on the crack
  RunReducedExplicit(Permeameter(1e6), 500, "crack 1e6");
  RunBackwardEulerToSteadyState(Permeameter(1e6), Permeameter(1e6), "crack 1e6");
}

TEST(Stability, SliverDomainsExplicitGovernorTakesTheTinyStepOrNamesTheSliver) {
  FlowNetwork net = SliverPermeameter();
  ExplicitSolver refusing = MakeExplicit(StepLimitPolicy::kRefuse);
  const auto limit = refusing.CriticalStep(net);
  ASSERT_TRUE(limit.ok());
  EXPECT_EQ(limit->limiting_domain, kSliver);
  EXPECT_NEAR(limit->dt_crit, 1e-12 * UniformCriticalStep(), 1e-9 * 1e-12 * UniformCriticalStep());

  const auto refused = refusing.Step(net, 0.9 * UniformCriticalStep());
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  const std::string m = refused.status().message();  // status() is a copy
  EXPECT_NE(m.find("at domain " + std::to_string(kSliver) + ":"), std::string::npos) << m;
  EXPECT_NE(m.find("volume floor"), std::string::npos) << m;
  EXPECT_NE(m.find("implicit solver"), std::string::npos) << m;

  RunReducedExplicit(SliverPermeameter(), 500, "sliver");

  // Sub-cycling a 1 us DEM step would need ~1e13 steps of the sliver's limit: refused, with the
  // remedy.
  const auto advanced = refusing.Advance(net, 1e-6);
  ASSERT_FALSE(advanced.ok());
  EXPECT_EQ(advanced.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(advanced.status().message().find("use the implicit solver"), std::string::npos)
      << advanced.status().message();
}

// Regression: Advance's refusal once did not name the limiting domain (unlike Step()'s), so a user
// could not tell which sliver to floor or merge.
TEST(Stability, SliverAdvanceRefusalNamesTheLimitingDomain) {
  FlowNetwork net = SliverPermeameter();
  ExplicitSolver solver = MakeExplicit(StepLimitPolicy::kRefuse);
  const auto advanced = solver.Advance(net, 1e-6);
  ASSERT_FALSE(advanced.ok());
  EXPECT_NE(advanced.status().message().find("domain " + std::to_string(kSliver)),
            std::string::npos)
      << advanced.status().message();
}

TEST(Stability, SliverDomainsBackwardEulerStaysMonotone) {
  RunBackwardEulerToSteadyState(SliverPermeameter(), SliverPermeameter(), "sliver");
}

}  // namespace
}  // namespace seep::core
