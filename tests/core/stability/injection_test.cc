// Injection at a high rate into a closed network (issue 7; docs/physics.md §1.2, R1): nothing
// leaves, so the storage-weighted mean pressure rises exactly as
//
//   d/dt (sum V_s P / sum V_s) = K_f Q / sum V_s,
//
// from the first step on, for both schemes (their updates conserve sum V_s P / K_f exactly). Once
// the start-up transient has decayed every domain rises at that rate. From a uniform start the
// increments obey the source-free update (explicit below dt_crit: a non-negative matrix; backward
// Euler: A^-1 >= 0), so no domain's pressure ever falls.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <variant>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/flow/time_step_limit.h"
#include "stability_invariants.h"

namespace seep::core {
namespace {

using stability::kWater;
constexpr double kRate = 1e-4;  // Q, m^2/s: refills the whole pore space every second
constexpr int kInjectionSide = 10;
constexpr std::int32_t kSourceDomain = 3 * kInjectionSide + 2;

FlowNetwork ClosedLatticeWithSource() {
  testing::LatticeParams lp;
  lp.bulk_modulus = kWater;
  FlowNetwork net =
      testing::MakeOrDie(testing::MakeSquareLatticeData(kInjectionSide, kInjectionSide, lp));
  EXPECT_TRUE(net.SetSource(kSourceDomain, kRate).ok());
  return net;
}

double StorageWeightedMean(const FlowNetwork& net, double* total_volume) {
  double vp = 0.0, v = 0.0;
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    vp += net.pore_volume()[d] * net.pressure()[d];
    v += net.pore_volume()[d];
  }
  *total_volume = v;
  return vp / v;
}

struct Case {
  const char* name;
  bool implicit;
  double dt_over_crit;
  int steps;
};

TEST(Stability, InjectionIntoClosedNetworkRaisesPressureAtTheAnalyticRate) {
  // Explicit at 0.9 dt_crit needs ~1300 steps for the start-up mode (decay 0.978 per step on this
  // 10 x 10 lattice) to fall below 1e-12; backward Euler at 1000 dt_crit about ten.
  for (const Case c : {Case{"explicit", false, 0.9, 3000}, Case{"implicit", true, 1e3, 40}}) {
    SCOPED_TRACE(c.name);
    FlowNetwork net = ClosedLatticeWithSource();
    double total_volume = 0.0;
    const double mean0 = StorageWeightedMean(net, &total_volume);
    const double rate = kWater * kRate / total_volume;  // Pa/s
    ExplicitSolverOptions eopt;
    eopt.bulk_modulus = kWater;
    eopt.safety_factor = 1.0;
    ImplicitSolverOptions iopt;
    iopt.bulk_modulus = kWater;
    using AnySolver = std::variant<ExplicitSolver, ImplicitSolver>;
    AnySolver solver = c.implicit ? AnySolver(ImplicitSolver::Create(iopt).value())
                                  : AnySolver(ExplicitSolver::Create(eopt).value());
    const double dt = c.dt_over_crit * ComputeCriticalTimeStep(net, kWater, {})->dt_crit;

    stability::FluidLedger ledger(net, kWater, {});
    std::vector<double> previous(net.pressure().begin(), net.pressure().end());
    double t = 0.0, worst_mean = 0.0, worst_local = 0.0;
    for (int step = 1; step <= c.steps; ++step) {
      const auto r = std::visit([&](auto& s) { return ledger.Step(s, net, dt); }, solver);
      ASSERT_TRUE(r.ok()) << r.status().ToString();
      ASSERT_EQ(r->source_inflow, kRate);
      t += r->dt;
      ASSERT_TRUE(stability::AllFinite(net));
      double v = 0.0;
      const double rise = StorageWeightedMean(net, &v) - mean0;
      const double mean_error = std::abs(rise - rate * t) / (rate * t);
      worst_mean = std::max(worst_mean, mean_error);
      ASSERT_LE(mean_error, 1e-10) << "step " << step;
      const double expected_increment = rate * r->dt;
      for (std::size_t d = 0; d < net.num_domains(); ++d) {
        const double increment = net.pressure()[d] - previous[d];
        ASSERT_GE(increment, -1e-12 * expected_increment) << "domain " << d << " step " << step;
        if (step == c.steps) {
          const double local = std::abs(increment - expected_increment) / expected_increment;
          worst_local = std::max(worst_local, local);
          EXPECT_LE(local, 1e-10) << "domain " << d;
        }
        previous[d] = net.pressure()[d];
      }
    }
    EXPECT_TRUE(ledger.Conserved(net));
    EXPECT_TRUE(ledger.SolverReportWithin());
    stability::PrintMeasured(std::string(c.name) + " injection mean-rise error", worst_mean);
    stability::PrintMeasured(std::string(c.name) + " injection late local-rate error", worst_local);
    stability::PrintMeasured(std::string(c.name) + " injection cumulative mass error",
                             ledger.CumulativeError(net));
  }
}

}  // namespace
}  // namespace seep::core
