// Real water (K_f = 2.2e9 Pa) on fine grains: the explicit critical step (about 2e-10 s here) lies
// four decades below a DEM step of 1e-6 s (docs/physics.md §4.2-4.3). The explicit solver must
// sub-cycle (Advance) or reduce (kReduce) and stay bounded and conservative; backward Euler must
// take the whole DEM step at once and stay monotone.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/steady_state_solver.h"
#include "stability_invariants.h"
#include "stability_networks.h"

namespace seep::core {
namespace {

using stability::FluidLedger;
using stability::kMassTolerance;

using stability::kWater;
constexpr double kDemStep = 1e-6;    // s, a typical mechanical step (docs/physics.md §4.2)
constexpr double kStiffInlet = 1e6;  // Pa
constexpr int kColumns = 12;
constexpr int kRows = 10;

// R = 0.1 mm grains, k = 1e-12 m^2: a = 13 um, C = 1e-9 m^2/(Pa s), V_p = 1.6e-9 m^2 on the
// honeycomb of a hex packing, so dt_crit = V_p / (3 K_f C) = 2.4e-10 s.
testing::LatticeParams FineGrains() {
  testing::LatticeParams lp;
  lp.radius = 1e-4;
  lp.bulk_modulus = kWater;
  return lp;
}

FlowNetwork FineHoneycombPermeameter() {
  FlowNetworkData d = testing::MakeHoneycombData(kColumns, kRows, FineGrains());
  stability::MakePermeameter(d, kColumns, kRows, kStiffInlet, 0.0);
  return testing::MakeOrDie(std::move(d));
}

ExplicitSolver MakeExplicit(StepLimitPolicy policy, double safety) {
  ExplicitSolverOptions opt;
  opt.bulk_modulus = kWater;
  opt.policy = policy;
  opt.safety_factor = safety;
  auto s = ExplicitSolver::Create(opt);
  EXPECT_TRUE(s.ok()) << s.status().ToString();
  return std::move(s).value();
}

TEST(Stability, StiffWaterExplicitSubCyclesDemStepsBoundedAndConservative) {
  FlowNetwork net = FineHoneycombPermeameter();
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  ExplicitSolver advancing = MakeExplicit(StepLimitPolicy::kRefuse, 0.9);
  ExplicitSolver stepping = MakeExplicit(StepLimitPolicy::kRefuse, 0.9);
  const auto limit = advancing.CriticalStep(net);
  ASSERT_TRUE(limit.ok());
  ASSERT_LT(limit->dt_crit, 1e-3 * kDemStep);  // the hard case: far below the DEM step
  const auto expected_sub_steps =
      static_cast<std::int64_t>(std::ceil(kDemStep / (0.9 * limit->dt_crit)));

  FlowNetwork replay = net;  // the same run as single Step() calls, for the cumulative budget
  FluidLedger ledger(replay, kWater, {});
  double worst_advance = 0.0;
  for (int dem_step = 0; dem_step < 4; ++dem_step) {
    const auto r = advancing.Advance(net, kDemStep);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    EXPECT_EQ(r->sub_steps, expected_sub_steps);
    EXPECT_LE(r->sub_step, 0.9 * limit->dt_crit * (1 + 1e-15));  // duration / n may round up
    EXPECT_NEAR(r->sub_step * static_cast<double>(r->sub_steps), kDemStep, 1e-15 * kDemStep);
    EXPECT_LE(r->max_mass_balance_error, kMassTolerance);
    worst_advance = std::max(worst_advance, r->max_mass_balance_error);
    ASSERT_TRUE(stability::AllFinite(net));
    ASSERT_TRUE(stability::WithinBounds(net, bounds));
    for (std::int64_t k = 0; k < r->sub_steps; ++k) {
      const auto s = ledger.Step(stepping, replay, std::min(r->sub_step, 0.9 * limit->dt_crit));
      ASSERT_TRUE(s.ok()) << s.status().ToString();
    }
    // Advance is exactly its sub-steps: same pressures bit for bit.
    for (std::size_t d = 0; d < net.num_domains(); ++d) {
      ASSERT_EQ(net.pressure()[d], replay.pressure()[d]) << "domain " << d;
    }
  }
  EXPECT_TRUE(ledger.Conserved(replay));
  EXPECT_TRUE(ledger.SolverReportWithin());
  // The front has crossed the sample: interior pressure really moved (not a frozen run).
  EXPECT_GT(ComputePressureRange(net).max, 0.5 * kStiffInlet);
  stability::PrintMeasured("stiff explicit worst step mass error", worst_advance);
  stability::PrintMeasured("stiff explicit cumulative mass error", ledger.CumulativeError(replay));

  // One Step() of a whole DEM step: kRefuse refuses, kReduce takes exactly safety * dt_crit.
  ExplicitSolver refusing = MakeExplicit(StepLimitPolicy::kRefuse, 0.9);
  const std::vector<double> before(net.pressure().begin(), net.pressure().end());
  const auto refused = refusing.Step(net, kDemStep);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(std::vector<double>(net.pressure().begin(), net.pressure().end()), before);
  ExplicitSolver reducing = MakeExplicit(StepLimitPolicy::kReduce, 0.9);
  const auto reduced = reducing.Step(net, kDemStep);
  ASSERT_TRUE(reduced.ok());
  EXPECT_EQ(reduced->dt, 0.9 * limit->dt_crit);
  EXPECT_EQ(reduced->dt_requested, kDemStep);
  EXPECT_LE(reduced->mass_balance_error, kMassTolerance);
  EXPECT_TRUE(stability::WithinBounds(net, bounds));
}

TEST(Stability, StiffWaterSubCyclingSpreadsTheDemVolumeChangeConservatively) {
  // The skeleton compacts every domain by 1e-6 of its volume over each DEM step (dV < 0): Advance
  // spreads dV evenly over its sub-steps. The budget then includes dV; the pressure may exceed the
  // inlet (compaction is a source), so only the budget, finiteness and the replay are asserted.
  FlowNetwork net = FineHoneycombPermeameter();
  std::vector<double> dv(net.num_domains(), 0.0);
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    if (net.role()[d] != DomainRole::kFixedPressure) dv[d] = -1e-6 * net.pore_volume()[d];
  }
  ExplicitSolver advancing = MakeExplicit(StepLimitPolicy::kRefuse, 0.9);
  ExplicitSolver stepping = MakeExplicit(StepLimitPolicy::kRefuse, 0.9);
  const double allowed = 0.9 * advancing.CriticalStep(net)->dt_crit;
  FlowNetwork replay = net;
  FluidLedger ledger(replay, kWater, {});
  std::vector<double> share(dv.size());
  for (int dem_step = 0; dem_step < 3; ++dem_step) {
    const auto r = advancing.Advance(net, kDemStep, dv);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_TRUE(stability::AllFinite(net));
    EXPECT_LE(r->max_mass_balance_error, kMassTolerance);
    // Advance's own split: dV / n per sub-step.
    for (std::size_t d = 0; d < dv.size(); ++d) {
      share[d] = dv[d] * (1.0 / static_cast<double>(r->sub_steps));
    }
    for (std::int64_t k = 0; k < r->sub_steps; ++k) {
      const double gross = stability::GrossBoundaryRate(replay);
      const auto s = stepping.Step(replay, std::min(r->sub_step, allowed), share);
      ASSERT_TRUE(s.ok()) << s.status().ToString();
      ledger.Record(replay, *s, gross);  // explicit: fluxes at the old pressures
    }
    for (std::size_t d = 0; d < net.num_domains(); ++d) {
      ASSERT_EQ(net.pressure()[d], replay.pressure()[d]) << "domain " << d;
    }
  }
  EXPECT_TRUE(ledger.Conserved(replay));
  EXPECT_TRUE(ledger.SolverReportWithin());
  // The compaction squeezed fluid out: the budget has something to close.
  EXPECT_NE(ledger.transported(), 0.0);
  stability::PrintMeasured("stiff explicit with dV net fluid moved (m^2)", ledger.transported());
  stability::PrintMeasured("stiff explicit with dV cumulative mass error",
                           ledger.CumulativeError(replay));
}

TEST(Stability, StiffWaterClosedNetworkSubCyclingKeepsItsFluid) {
  // A closed network (no boundary, random pressures up to 1 MPa): every sub-step only moves fluid
  // around, so the stored excess and the mass proxy stay put and the range can only shrink.
  FlowNetwork net = testing::MakeOrDie(testing::MakeRandomClosedData(60, 60, 11));
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  const double excess0 = *StoredFluidExcess(net, kWater, {});
  const double proxy0 = *FluidMassProxy(net, kWater, {});
  const double held0 = stability::FluidHeld(net, kWater, {});
  ExplicitSolver solver = MakeExplicit(StepLimitPolicy::kRefuse, 0.9);
  ASSERT_LT(solver.CriticalStep(net)->dt_crit, 1e-2 * kDemStep);
  for (int dem_step = 0; dem_step < 4; ++dem_step) {
    const auto r = solver.Advance(net, kDemStep);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    // Not r->max_mass_balance_error: near equilibrium the explicit solver's own figure is relative
    // to almost nothing (see DISABLED_ExplicitStepReportIsRelativeToTheFluidHeld); the budget is
    // measured from the pressures below instead.
    ASSERT_TRUE(stability::AllFinite(net));
    ASSERT_TRUE(stability::WithinBounds(net, bounds));
  }
  // Relative to the fluid held: rounding of P bounds what can be resolved (see the ledger).
  const double excess_error = std::abs(*StoredFluidExcess(net, kWater, {}) - excess0) / held0;
  const double proxy_error = std::abs(*FluidMassProxy(net, kWater, {}) - proxy0) / proxy0;
  const double worst = std::max(excess_error, proxy_error);
  EXPECT_LE(excess_error, kMassTolerance);
  EXPECT_LE(proxy_error, kMassTolerance);
  stability::PrintMeasured("stiff closed cumulative stored-excess error", worst);
}

TEST(Stability, StiffWaterBackwardEulerTakesWholeDemStepsMonotonically) {
  FlowNetwork net = FineHoneycombPermeameter();
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  ImplicitSolverOptions opt;
  opt.bulk_modulus = kWater;
  auto solver = ImplicitSolver::Create(opt);
  ASSERT_TRUE(solver.ok());
  FluidLedger ledger(net, kWater, {});
  std::vector<double> previous(net.pressure().begin(), net.pressure().end());
  double dt_over_crit = 0.0;
  for (int step = 0; step < 60; ++step) {
    const auto r = ledger.Step(*solver, net, kDemStep);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    dt_over_crit = r->dt / r->dt_crit;
    ASSERT_TRUE(stability::AllFinite(net));
    ASSERT_TRUE(stability::WithinBounds(net, bounds));
    // Start at 0 below the steady state: A^-1 >= 0 (M-matrix) makes every increment >= 0.
    for (std::size_t d = 0; d < net.num_domains(); ++d) {
      ASSERT_GE(net.pressure()[d], previous[d] - 1e-12 * kStiffInlet)
          << "step " << step << " d " << d;
      previous[d] = net.pressure()[d];
    }
  }
  EXPECT_GT(dt_over_crit, 1e3);
  EXPECT_TRUE(ledger.Conserved(net));
  EXPECT_TRUE(ledger.SolverReportWithin());
  // One DEM step is ~10 diffusion times of this 12-column sample (N^2 V_p / (K_f C) = 1e-7 s):
  // after 60 of them only the steady state is left, to rounding.
  FlowNetwork steady = FineHoneycombPermeameter();
  ASSERT_TRUE(SolveSteadyState(steady).ok());
  double worst = 0.0;
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    worst = std::max(worst, std::abs(net.pressure()[d] - steady.pressure()[d]) / kStiffInlet);
  }
  EXPECT_LE(worst, 1e-10);
  stability::PrintMeasured("stiff BE dt/dt_crit", dt_over_crit);
  stability::PrintMeasured("stiff BE worst step mass error", ledger.worst_step_error());
  stability::PrintMeasured("stiff BE cumulative mass error", ledger.CumulativeError(net));
  stability::PrintMeasured("stiff BE distance to steady state / p_in", worst);
}

}  // namespace
}  // namespace seep::core
