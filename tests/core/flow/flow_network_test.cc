// FlowNetwork validation, the steady solver, components and boundary helpers.
#include "seep/core/flow/flow_network.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "flow_test_networks.h"
#include "seep/core/flow/boundary_conditions.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/network_components.h"
#include "seep/core/flow/steady_state_solver.h"

namespace seep::core {
namespace {

using testing::AddDomain;
using testing::AddPipe;
using testing::LatticeParams;

FlowNetworkData ThreeDomains() {
  FlowNetworkData d;
  AddDomain(d, 2e-7, 1e-7, 0.0, DomainRole::kFixedPressure);
  AddDomain(d, 2e-7, 1e-7);
  AddDomain(d, 2e-7, 1e-7);
  AddPipe(d, 0, 1, 1e-3, 1e-5, 1e-9);
  AddPipe(d, 1, 2, 1e-3, 1e-5, 2e-9);
  return d;
}

void ExpectInvalid(const FlowNetworkData& d, const std::string& field) {
  const Status s = FlowNetwork::Validate(d);
  EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << field;
  EXPECT_NE(s.message().find(field), std::string::npos) << s.message();
}

TEST(FlowNetwork, ValidationNamesTheField) {
  ASSERT_TRUE(FlowNetwork::Validate(ThreeDomains()).ok());
  const double nan = std::numeric_limits<double>::quiet_NaN();
  {
    auto d = ThreeDomains();
    d.pore_volume[2] = -1e-7;
    ExpectInvalid(d, "flow.network.pore_volume[2]");
  }
  {
    auto d = ThreeDomains();
    d.apparent_volume[1] = nan;
    ExpectInvalid(d, "flow.network.apparent_volume[1]");
  }
  {
    auto d = ThreeDomains();
    d.pore_volume[1] = 3e-7;
    ExpectInvalid(d, "pore_volume[1]: exceeds apparent_volume");
  }
  {
    auto d = ThreeDomains();
    d.pressure[0] = std::numeric_limits<double>::infinity();
    ExpectInvalid(d, "flow.network.pressure[0]");
  }
  {
    auto d = ThreeDomains();
    d.pipe_domain_b[1] = 3;
    ExpectInvalid(d, "flow.network.pipe_domain_b[1]: domain index 3 out of range");
  }
  {
    auto d = ThreeDomains();
    d.pipe_domain_a[0] = -1;
    ExpectInvalid(d, "flow.network.pipe_domain_a[0]");
  }
  {
    auto d = ThreeDomains();
    d.pipe_domain_b[0] = 0;
    ExpectInvalid(d, "to itself");
  }
  {
    auto d = ThreeDomains();
    d.pipe_conductance[1] = 0.0;
    ExpectInvalid(d, "flow.network.pipe_conductance[1]");
  }
  {
    auto d = ThreeDomains();
    d.pipe_length[0] = 0.0;
    ExpectInvalid(d, "flow.network.pipe_length[0]");
  }
  {
    auto d = ThreeDomains();
    d.role.pop_back();
    ExpectInvalid(d, "flow.network.role: has 2 entries, expected 3");
  }
  {
    auto d = ThreeDomains();
    d.source_rate[1] = 1e-6;
    ExpectInvalid(d, "source_rate[1]: is 1e-06 but the domain's role is not kSource");
  }
  EXPECT_TRUE(FlowNetwork::Create(ThreeDomains()).ok());
}

TEST(FlowNetwork, ZeroStorageOfAFreeDomainIsRefusedBySolvers) {
  auto d = ThreeDomains();
  d.pore_volume[2] = 0.0;
  FlowNetwork net = testing::MakeOrDie(d);
  auto solver = ImplicitSolver::Create({});
  ASSERT_TRUE(solver.ok());
  const auto r = solver->Step(net, 1e-3);
  EXPECT_EQ(r.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(r.status().message().find("pore_volume[2]"), std::string::npos) << r.status().message();
}

TEST(FlowNetwork, MutationsDrawFreshVersionStamps) {
  FlowNetwork net = testing::MakeOrDie(ThreeDomains());
  FlowNetwork other = testing::MakeOrDie(ThreeDomains());
  EXPECT_NE(net.topology_version(), other.topology_version());
  const auto topo = net.topology_version();
  const auto coef = net.coefficient_version();
  net.mutable_pressure()[1] = 5.0;
  EXPECT_EQ(net.coefficient_version(), coef);
  net.mutable_pipe_conductance()[0] = 3e-9;
  EXPECT_NE(net.coefficient_version(), coef);
  EXPECT_EQ(net.topology_version(), topo);
  ASSERT_TRUE(net.SetFixedPressure(2, 1.0).ok());
  EXPECT_NE(net.topology_version(), topo);
  EXPECT_EQ(net.SetSource(7, 1.0).code(), StatusCode::kInvalidArgument);
}

TEST(FlowNetwork, SteadyChainIsLinearWithExactFlux) {
  const LatticeParams lp;
  const int n = 20;
  const double p_in = 1e5;
  FlowNetwork net = testing::MakeChain(n, lp, lp.SquareApparentVolume(), lp.SquarePoreVolume(),
                                       /*no_flow_end=*/false, p_in);
  for (const auto kind :
       {LinearSolverKind::kCholmodSupernodal, LinearSolverKind::kEigenSimplicialLdlt}) {
    SteadyStateOptions opt;
    opt.linear_solver = kind;
    const auto report = SolveSteadyState(net, opt);
    ASSERT_TRUE(report.ok()) << report.status().ToString();
    for (int i = 0; i <= n; ++i) {
      EXPECT_NEAR(net.pressure()[i], p_in * (1.0 - static_cast<double>(i) / n), 1e-10 * p_in);
    }
    const double q = lp.Conductance() * p_in / n;
    const BoundaryFluxes flux = ComputeBoundaryFluxes(net);
    ASSERT_EQ(flux.domain.size(), 2u);
    EXPECT_NEAR(flux.total_inflow, q, 1e-10 * q);
    EXPECT_NEAR(flux.total_outflow, q, 1e-10 * q);
    EXPECT_NEAR(report->boundary_inflow, 0.0, 1e-10 * q);
    EXPECT_LT(report->mass_balance_error, 1e-10);
  }
}

TEST(FlowNetwork, SteadySeriesConductancesGiveHarmonicFlux) {
  // Pipes in series: q = dp / sum(1/C_p); P_i drops by q/C_p across pipe p.
  FlowNetworkData d;
  const std::vector<double> c{1e-9, 4e-9, 2.5e-10, 7e-9};
  for (int i = 0; i <= 4; ++i) AddDomain(d, 1e-7, 1e-7);
  d.role[0] = d.role[4] = DomainRole::kFixedPressure;
  d.pressure[0] = 3e4;
  d.pressure[4] = -1e4;
  for (int i = 0; i < 4; ++i) AddPipe(d, i, i + 1, 1e-3, 1e-5, c[i]);
  FlowNetwork net = testing::MakeOrDie(d);
  ASSERT_TRUE(SolveSteadyState(net).ok());
  double resistance = 0.0;
  for (const double ci : c) resistance += 1.0 / ci;
  const double q = 4e4 / resistance;
  double p = 3e4;
  for (int i = 0; i < 4; ++i) {
    p -= q / c[i];
    EXPECT_NEAR(net.pressure()[i + 1], p, 1e-9 * 4e4);
  }
  EXPECT_NEAR(ComputeBoundaryFluxes(net).total_inflow, q, 1e-10 * q);
}

TEST(FlowNetwork, SquareLatticePermeabilityByConstruction) {
  // (nx-1)(ny-1) square-cell domains of an nx x ny disk packing, L = 2R, C = a^3/(24 mu R),
  // Dirichlet left/right columns, no flow top/bottom: k = a^3/(24 R) (physics.md §1.3).
  const LatticeParams lp;
  const int nx = 31, ny = 17;
  const int mx = nx - 1, my = ny - 1;
  FlowNetworkData d = testing::MakeSquareLatticeData(mx, my, lp);
  FlowNetwork net = testing::MakeOrDie(d);
  const double p_in = 2e5, p_out = 5e4;
  for (int j = 0; j < my; ++j) {
    ASSERT_TRUE(net.SetFixedPressure(j * mx, p_in).ok());
    ASSERT_TRUE(net.SetFixedPressure(j * mx + mx - 1, p_out).ok());
  }
  const auto report = SolveSteadyState(net);
  ASSERT_TRUE(report.ok()) << report.status().ToString();
  const BoundaryFluxes flux = ComputeBoundaryFluxes(net);
  EXPECT_NEAR(flux.total_inflow, flux.total_outflow, 1e-10 * flux.total_inflow);
  const double h = 2.0 * lp.radius;
  const double length = (mx - 1) * h;  // between the centroid lines of the Dirichlet columns
  const double height = my * h;        // tiled by the domain rows
  const auto k = DarcyPermeability(lp.viscosity, flux.total_inflow, length, height, p_in - p_out);
  ASSERT_TRUE(k.ok());
  const double a = lp.Aperture();
  const double k_expected = a * a * a / (24.0 * lp.radius);
  EXPECT_NEAR(*k, k_expected, 1e-8 * k_expected);
  EXPECT_NEAR(k_expected, lp.permeability, 1e-12 * lp.permeability);
}

TEST(FlowNetwork, ClosedComponentWithoutDirichletNodeIsAClearError) {
  // Domains 0-1-2 anchored by fixed node 0; domains 3-4 form a closed island.
  auto d = ThreeDomains();
  AddDomain(d, 2e-7, 1e-7, 10.0);
  AddDomain(d, 2e-7, 2e-8, 40.0);
  AddPipe(d, 3, 4, 1e-3, 1e-5, 1e-9);
  FlowNetwork net = testing::MakeOrDie(d);
  const NetworkComponents comps = FindNetworkComponents(net);
  EXPECT_EQ(comps.num_components, 2);
  EXPECT_EQ(comps.component_of_domain[0], -1);
  EXPECT_EQ(comps.anchored[0], 1);
  EXPECT_EQ(comps.anchored[1], 0);

  const auto failed = SolveSteadyState(net);
  EXPECT_EQ(failed.status().code(), StatusCode::kFailedPrecondition);
  EXPECT_NE(failed.status().message().find("component 1 (containing domain 3) has no "
                                           "fixed-pressure domain"),
            std::string::npos)
      << failed.status().message();

  SteadyStateOptions opt;
  opt.closed_components = ClosedComponentPolicy::kConserveStoredFluid;
  const auto ok = SolveSteadyState(net, opt);
  ASSERT_TRUE(ok.ok()) << ok.status().ToString();
  const double mean = (1e-7 * 10.0 + 2e-8 * 40.0) / (1e-7 + 2e-8);
  EXPECT_NEAR(net.pressure()[3], mean, 1e-12 * mean);
  EXPECT_NEAR(net.pressure()[4], mean, 1e-12 * mean);
  EXPECT_NEAR(net.pressure()[1], 0.0, 1e-12);
  EXPECT_EQ(ok->num_closed_components, 1);
}

TEST(FlowNetwork, ClosedComponentWithBalancedSourcesConservesFluid) {
  // A closed pair with +Q into 0 and -Q out of 1: steady P0 - P1 = Q/C, storage-weighted mean
  // kept; an unbalanced source has no steady state.
  FlowNetworkData d;
  AddDomain(d, 1e-7, 1e-7, 100.0);
  AddDomain(d, 3e-7, 3e-7, 300.0);
  AddPipe(d, 0, 1, 1e-3, 1e-5, 2e-9);
  FlowNetwork net = testing::MakeOrDie(d);
  ASSERT_TRUE(net.SetSource(0, 4e-6).ok());
  ASSERT_TRUE(net.SetSource(1, -4e-6).ok());
  SteadyStateOptions opt;
  opt.closed_components = ClosedComponentPolicy::kConserveStoredFluid;
  ASSERT_TRUE(SolveSteadyState(net, opt).ok());
  const double mean = (1e-7 * 100.0 + 3e-7 * 300.0) / 4e-7;
  EXPECT_NEAR(net.pressure()[0] - net.pressure()[1], 4e-6 / 2e-9, 1e-9 * 2e3);
  EXPECT_NEAR((1e-7 * net.pressure()[0] + 3e-7 * net.pressure()[1]) / 4e-7, mean, 1e-9 * mean);
  ASSERT_TRUE(net.SetSource(1, -1e-6).ok());
  EXPECT_EQ(SolveSteadyState(net, opt).status().code(), StatusCode::kFailedPrecondition);
}

TEST(FlowNetwork, HydrostaticHelperFixesPressureFromElevation) {
  auto d = ThreeDomains();
  FlowNetwork net = testing::MakeOrDie(d);
  const std::vector<double> y{0.0, 0.5, 2.0};
  HydrostaticGradient h;
  h.reference_pressure = 1e5;
  h.reference_elevation = 2.0;
  h.density = 1000.0;
  h.gravity = 9.81;
  const std::vector<std::int32_t> which{0, 2};
  ASSERT_TRUE(ApplyHydrostaticPressure(net, which, y, h).ok());
  EXPECT_EQ(net.role()[0], DomainRole::kFixedPressure);
  EXPECT_EQ(net.role()[1], DomainRole::kFree);
  EXPECT_EQ(net.role()[2], DomainRole::kFixedPressure);
  EXPECT_DOUBLE_EQ(net.pressure()[0], 1e5 + 1000.0 * 9.81 * 2.0);
  EXPECT_DOUBLE_EQ(net.pressure()[2], 1e5);
  const std::vector<double> short_y{0.0};
  EXPECT_EQ(ApplyHydrostaticPressure(net, which, short_y, h).code(), StatusCode::kInvalidArgument);
}

TEST(FlowNetwork, ImplicitSolverReusesAnalysisAndFactorization) {
  const LatticeParams lp;
  FlowNetwork net =
      testing::MakeChain(10, lp, lp.SquareApparentVolume(), lp.SquarePoreVolume(), false);
  auto solver = ImplicitSolver::Create({});
  ASSERT_TRUE(solver.ok());
  for (int s = 0; s < 3; ++s) ASSERT_TRUE(solver->Step(net, 1e-6).ok());
  EXPECT_EQ(solver->stats().analyses, 1);
  EXPECT_EQ(solver->stats().factorizations, 1);
  EXPECT_EQ(solver->stats().solves, 3);
  ASSERT_TRUE(solver->Step(net, 2e-6).ok());  // new dt: refactorise only
  EXPECT_EQ(solver->stats().analyses, 1);
  EXPECT_EQ(solver->stats().factorizations, 2);
  std::vector<double> a(net.num_pipes(), lp.Aperture() * 1.1);
  ASSERT_TRUE(net.SetApertures(a, lp.viscosity).ok());  // new conductances: refactorise only
  ASSERT_TRUE(solver->Step(net, 2e-6).ok());
  EXPECT_EQ(solver->stats().analyses, 1);
  EXPECT_EQ(solver->stats().factorizations, 3);
  ASSERT_TRUE(net.SetFixedPressure(5, 0.5).ok());  // new unknowns: re-analyse
  ASSERT_TRUE(solver->Step(net, 2e-6).ok());
  EXPECT_EQ(solver->stats().analyses, 2);
  EXPECT_EQ(solver->stats().factorizations, 4);
  EXPECT_EQ(solver->stats().solves, 6);
}

TEST(FlowNetwork, LinearSolversAgreeAndRunsAreBitIdentical) {
  auto run = [](LinearSolverKind kind) {
    FlowNetworkData d = testing::MakeRandomClosedData(300, 400, 7);
    d.role[0] = DomainRole::kFixedPressure;
    FlowNetwork net = testing::MakeOrDie(d);
    ImplicitSolverOptions opt;
    opt.linear_solver = kind;
    auto solver = ImplicitSolver::Create(opt);
    EXPECT_TRUE(solver.ok());
    for (int s = 0; s < 5; ++s) EXPECT_TRUE(solver->Step(net, 1e-6).ok());
    return std::vector<double>(net.pressure().begin(), net.pressure().end());
  };
  const auto a = run(LinearSolverKind::kCholmodSupernodal);
  const auto b = run(LinearSolverKind::kEigenSimplicialLdlt);
  const auto a2 = run(LinearSolverKind::kCholmodSupernodal);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_NEAR(a[i], b[i], 1e-9 * 1e6);
  EXPECT_EQ(a, a2);  // bit-identical run to run
}

TEST(FlowNetwork, ExplicitAdvanceSubCyclesWithinTheLimit) {
  // A closed random network deformed by dV over a span of 37.3 dt_crit: ceil(37.3/0.9) sub-steps,
  // and the stored fluid changes by exactly -sum dV.
  FlowNetwork net = testing::MakeOrDie(testing::MakeRandomClosedData(50, 40, 3));
  auto solver = ExplicitSolver::Create({});
  ASSERT_TRUE(solver.ok());
  const double dt_crit = solver->CriticalStep(net)->dt_crit;
  std::vector<double> dv(net.num_domains());
  double dv_total = 0.0;
  for (std::size_t d = 0; d < dv.size(); ++d) {
    dv[d] = 1e-11 * std::sin(static_cast<double>(d));
    dv_total += dv[d];
  }
  const double kf = solver->options().bulk_modulus;
  const double before = *StoredFluidExcess(net, kf, {});
  const auto r = solver->Advance(net, 37.3 * dt_crit, dv);
  ASSERT_TRUE(r.ok()) << r.status().ToString();
  EXPECT_EQ(r->sub_steps, static_cast<std::int64_t>(std::ceil(37.3 / 0.9)));
  EXPECT_LE(r->sub_step, 0.9 * dt_crit * (1.0 + 1e-15));
  EXPECT_LT(r->max_mass_balance_error, 1e-12);
  const double after = *StoredFluidExcess(net, kf, {});
  EXPECT_NEAR(after - before, -dv_total, 1e-12 * before);
}

}  // namespace
}  // namespace seep::core
