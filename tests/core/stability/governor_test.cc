// The explicit governor around the critical step on a heterogeneous, non-bipartite network
// (docs/physics.md §4.1, S1). V10 (flow/verification_stability_test.cc) already shows on bipartite
// networks that 1.05 dt_crit grows and that kRefuse/kReduce stop it; here: the limit is the
// exact minimum of V_s,i / (K_f sum_j C_ij) and names its domain, 0.99 dt_crit keeps the maximum
// principle and the fluid budget on an irregular network, a refusal leaves the state untouched and
// its message says why and what to change, and kReduce runs at exactly safety * dt_crit.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/storage_volume.h"
#include "stability_invariants.h"
#include "stability_networks.h"

namespace seep::core {
namespace {

using stability::kWater;

// A 14 x 10 square-lattice permeameter with volumes and apertures scattered over a factor of 4
// either way, plus diagonal pipes in every other cell (odd cycles: not bipartite).
FlowNetwork IrregularNetwork() {
  testing::LatticeParams lp;
  lp.bulk_modulus = kWater;
  FlowNetwork lattice = stability::MakeHeterogeneousLattice(14, 10, lp, 4.0, 21, 1e5, 0.0);
  FlowNetworkData d = lattice.data();
  for (int j = 0; j + 1 < 10; j += 2) {
    for (int i = 1; i + 1 < 13; i += 2) {
      testing::AddPipe(d, j * 14 + i, (j + 1) * 14 + i + 1, 2e-3, 0.5 * lp.Aperture(),
                       0.125 * lp.Conductance());
    }
  }
  return testing::MakeOrDie(std::move(d));
}

// min_i V_s,i / (K_f sum_j C_ij), computed here from the arrays, and its argmin.
std::pair<double, std::int32_t> IndependentLimit(const FlowNetwork& net) {
  std::vector<double> sum_c(net.num_domains(), 0.0);
  for (std::size_t p = 0; p < net.num_pipes(); ++p) {
    sum_c[net.pipe_domain_a()[p]] += net.pipe_conductance()[p];
    sum_c[net.pipe_domain_b()[p]] += net.pipe_conductance()[p];
  }
  double best = std::numeric_limits<double>::infinity();
  std::int32_t arg = -1;
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    if (net.role()[d] == DomainRole::kFixedPressure) continue;
    const double dt = net.pore_volume()[d] / (kWater * sum_c[d]);
    if (dt < best) {
      best = dt;
      arg = static_cast<std::int32_t>(d);
    }
  }
  return {best, arg};
}

ExplicitSolver Make(StepLimitPolicy policy, double safety = 1.0) {
  ExplicitSolverOptions opt;
  opt.bulk_modulus = kWater;
  opt.policy = policy;
  opt.safety_factor = safety;
  return std::move(ExplicitSolver::Create(opt)).value();
}

TEST(Stability, GovernorLimitIsTheExactMinimumAndNamesItsDomain) {
  const FlowNetwork net = IrregularNetwork();
  ExplicitSolver solver = Make(StepLimitPolicy::kRefuse);
  const auto limit = solver.CriticalStep(net);
  ASSERT_TRUE(limit.ok());
  const auto [dt_crit, domain] = IndependentLimit(net);
  EXPECT_NEAR(limit->dt_crit, dt_crit, 1e-14 * dt_crit);  // same formula, summed in another order
  EXPECT_EQ(limit->limiting_domain, domain);
}

TEST(Stability, ExplicitAtPoint99CriticalStaysBoundedAndConservative) {
  FlowNetwork net = IrregularNetwork();
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  // Advise-only so that nothing but the step itself decides (0.99 is below the limit anyway).
  ExplicitSolver solver = Make(StepLimitPolicy::kAdviseOnly);
  const double dt = 0.99 * solver.CriticalStep(net)->dt_crit;
  stability::FluidLedger ledger(net, kWater, {});
  for (int step = 0; step < 3000; ++step) {
    const auto r = ledger.Step(solver, net, dt);
    ASSERT_TRUE(r.ok()) << r.status().ToString();
    ASSERT_FALSE(r->limit_exceeded);
    ASSERT_TRUE(stability::AllFinite(net));
    ASSERT_TRUE(stability::WithinBounds(net, bounds)) << "step " << step;
  }
  EXPECT_TRUE(ledger.Conserved(net));
  EXPECT_TRUE(ledger.SolverReportWithin());
  stability::PrintMeasured("0.99 dt_crit worst step mass error", ledger.worst_step_error());
  stability::PrintMeasured("0.99 dt_crit cumulative mass error", ledger.CumulativeError(net));
}

TEST(Stability, ExplicitAtOnePoint05CriticalIsRefusedWithReasonOrReduced) {
  FlowNetwork net = IrregularNetwork();
  const stability::PressureBounds bounds = stability::BoundsOf(net);
  const auto [dt_crit, domain] = IndependentLimit(net);
  const double dt = 1.05 * dt_crit;

  // kRefuse: FAILED_PRECONDITION, state untouched, the message names the limit, the limiting
  // domain with its V_s and sum C, and the remedies.
  ExplicitSolver refusing = Make(StepLimitPolicy::kRefuse, 0.9);
  const std::vector<double> before(net.pressure().begin(), net.pressure().end());
  const auto refused = refusing.Step(net, dt);
  ASSERT_FALSE(refused.ok());
  EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_EQ(std::vector<double>(net.pressure().begin(), net.pressure().end()), before);
  const std::string m = refused.status().message();  // status() is a copy
  for (const std::string& part :
       {std::string("flow.explicit: dt = "), std::string("dt_crit"),
        "at domain " + std::to_string(domain) + ":", std::string("V_s = "), std::string("sum C = "),
        std::string("Reduce dt"), std::string("implicit solver"),
        std::string("a volume floor: scene.solver.storage_floor_fraction"),
        std::string("cap the aperture")}) {
    EXPECT_NE(m.find(part), std::string::npos) << "missing '" << part << "' in: " << m;
  }

  // kReduce: every step runs at exactly safety * dt_crit and the run stays in bounds.
  for (const double safety : {1.0, 0.9}) {
    FlowNetwork run = IrregularNetwork();
    ExplicitSolver reducing = Make(StepLimitPolicy::kReduce, safety);
    const double allowed = safety * reducing.CriticalStep(run)->dt_crit;
    stability::FluidLedger ledger(run, kWater, {});
    for (int step = 0; step < 1500; ++step) {
      const auto r = ledger.Step(reducing, run, dt);
      ASSERT_TRUE(r.ok()) << r.status().ToString();
      ASSERT_EQ(r->dt, allowed);
      ASSERT_EQ(r->dt_requested, dt);
      ASSERT_EQ(r->limiting_domain, domain);
      ASSERT_TRUE(stability::AllFinite(run));
      ASSERT_TRUE(stability::WithinBounds(run, bounds)) << "safety " << safety << " step " << step;
    }
    EXPECT_TRUE(ledger.Conserved(run)) << "safety " << safety;
    EXPECT_TRUE(ledger.SolverReportWithin()) << "safety " << safety;
  }
}

}  // namespace
}  // namespace seep::core
