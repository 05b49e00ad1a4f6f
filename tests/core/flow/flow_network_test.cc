// FlowNetwork validation, the steady solver, components and boundary helpers, and the explicit
// solver after coefficient edits.
#include "seep/core/flow/flow_network.h"

#include <gtest/gtest.h>
#include <omp.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <limits>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/boundary_conditions.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/network_components.h"
#include "seep/core/flow/steady_state_solver.h"
#include "seep/core/flow/time_step_limit.h"

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

// On a network large enough for the one-region check on the threads: every bad coefficient is
// still named, in the second thread's half too, and of two, the one the ordered checks reach
// first (the volumes before the pipes).
TEST(FlowNetwork, CoefficientChecksOnThreadsNameTheFirstFailure) {
  const LatticeParams lp;
  const FlowNetworkData good = testing::MakeSquareLatticeData(100, 100, lp);
  ASSERT_GT(good.pipe_conductance.size(), 8192u);
  const int before = omp_get_max_threads();
  omp_set_num_threads(2);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::size_t late_domain = good.pressure.size() - 3;
  const std::size_t late_pipe = good.pipe_conductance.size() - 5;
  FlowNetworkData weighted = good;
  weighted.pipe_head_offset.assign(good.pipe_conductance.size(), 0.5);
  EXPECT_TRUE(FlowNetwork::ValidateCoefficients(good).ok());
  EXPECT_TRUE(FlowNetwork::ValidateCoefficients(weighted).ok());
  // The message names field[index], then says `why`.
  const auto expect_named = [](const FlowNetworkData& d, const char* field, std::size_t index,
                               const char* why = "") {
    std::string named = field;
    named += '[';
    named += std::to_string(index);
    named += ']';
    named += why;
    const Status s = FlowNetwork::ValidateCoefficients(d);
    EXPECT_EQ(s.code(), StatusCode::kInvalidArgument) << named;
    EXPECT_NE(s.message().find(named), std::string::npos) << s.message();
  };
  {
    FlowNetworkData d = good;
    d.apparent_volume[late_domain] = nan;
    expect_named(d, "apparent_volume", late_domain);
  }
  {
    FlowNetworkData d = good;
    d.pore_volume[late_domain] = -1.0;
    expect_named(d, "pore_volume", late_domain);
  }
  {
    FlowNetworkData d = good;
    d.pore_volume[late_domain] = 2.0 * d.apparent_volume[late_domain];
    expect_named(d, "pore_volume", late_domain, ": exceeds apparent_volume");
  }
  {
    FlowNetworkData d = good;
    d.source_rate[late_domain] = 1e-9;
    expect_named(d, "source_rate", late_domain, ": is 1e-09 but the domain's role is not kSource");
  }
  {
    FlowNetworkData d = good;
    d.pipe_length[late_pipe] = 0.0;
    expect_named(d, "pipe_length", late_pipe);
  }
  {
    FlowNetworkData d = good;
    d.pipe_aperture[late_pipe] = nan;
    expect_named(d, "pipe_aperture", late_pipe);
  }
  {
    FlowNetworkData d = weighted;
    d.pipe_head_offset[late_pipe] = nan;
    expect_named(d, "pipe_head_offset", late_pipe);
  }
  {
    FlowNetworkData d = good;
    d.pipe_conductance[late_pipe] = 0.0;
    expect_named(d, "pipe_conductance", late_pipe);
  }
  {
    // Two failures: a pipe early in the list and a domain late in it; the volumes come first.
    FlowNetworkData d = good;
    d.pipe_conductance[3] = -1.0;
    d.apparent_volume[late_domain] = -1.0;
    expect_named(d, "apparent_volume", late_domain);
  }
  omp_set_num_threads(before);
}

// The member ValidateCoefficients passes over the values other than the volumes only when they
// changed since they last passed, other than by a write that checked itself; its answer and message
// are always the static one's, which checks everything. Run on one and on two threads (the lattice
// is above the team threshold).
TEST(FlowNetwork, ValidateCoefficientsAfterCheckedWritesGivesTheFullChecksAnswer) {
  const LatticeParams lp;
  const FlowNetworkData good = testing::MakeSquareLatticeData(100, 100, lp);
  const std::size_t pipes = good.pipe_conductance.size();
  ASSERT_GT(pipes, 8192u);
  const int before = omp_get_max_threads();
  for (const int threads : {1, 2}) {
    omp_set_num_threads(threads);
    const auto expect_same = [&](const FlowNetwork& net, const std::string& named) {
      const Status member = net.ValidateCoefficients();
      const Status full = FlowNetwork::ValidateCoefficients(net.data());
      EXPECT_EQ(member.code(), full.code()) << named << " on " << threads;
      EXPECT_EQ(member.message(), full.message()) << named << " on " << threads;
      if (named.empty()) {
        EXPECT_TRUE(member.ok()) << member.message();
      } else {
        EXPECT_NE(member.message().find(named), std::string::npos) << member.message();
      }
    };
    Result<FlowNetwork> created = FlowNetwork::Create(good);
    ASSERT_TRUE(created.ok());
    FlowNetwork net = std::move(created).value();
    expect_same(net, "");  // the pipes pass: from here on they are known to
    const std::vector<double> apertures(pipes, 2e-5);
    ASSERT_TRUE(net.SetApertures(apertures, 1e-3).ok());
    expect_same(net, "");
    {  // a bad volume after a checked aperture write is still found
      FlowNetwork edited = net;
      edited.mutable_pore_volume()[17] = -1.0;
      expect_same(edited, "pore_volume[17]");
    }
    {  // a conductance written through the span is checked again, also after a pass
      FlowNetwork edited = net;
      edited.mutable_pipe_conductance()[pipes - 5] = 0.0;
      expect_same(edited, "pipe_conductance[" + std::to_string(pipes - 5) + "]");
      ASSERT_TRUE(
          edited.SetApertures(apertures, 1e-3).ok());  // checked, but over an unchecked state
      edited.mutable_pipe_conductance()[pipes - 5] = 0.0;
      expect_same(edited, "pipe_conductance");
    }
    {  // an aperture whose cube underflows: SetApertures takes it, the check names the conductance
      FlowNetwork edited = net;
      std::vector<double> tiny = apertures;
      tiny[pipes - 2] = 1e-110;
      ASSERT_TRUE(edited.SetApertures(tiny, 1e-3).ok());
      expect_same(edited, "pipe_conductance[" + std::to_string(pipes - 2) + "]");
      ASSERT_TRUE(edited.SetApertures(apertures, 1e-3).ok());  // mended: passes again
      expect_same(edited, "");
    }
    {  // a head offset that is not finite is refused where it is set
      FlowNetwork edited = net;
      std::vector<double> heads(pipes, 0.25);
      ASSERT_TRUE(edited.SetPipeHeadOffsets(heads).ok());
      expect_same(edited, "");
      heads[3] = std::numeric_limits<double>::infinity();
      EXPECT_FALSE(edited.SetPipeHeadOffsets(heads).ok());
      expect_same(edited, "");
    }
    {  // the role edits keep the rates and roles right: they check themselves
      FlowNetwork edited = net;
      ASSERT_TRUE(edited.SetSource(5, 1e-9).ok());
      expect_same(edited, "");
      ASSERT_TRUE(edited.SetFixedPressure(6, 1e3).ok());
      ASSERT_TRUE(edited.SetFree(5).ok());
      expect_same(edited, "");
      edited.mutable_apparent_volume()[5] = std::numeric_limits<double>::quiet_NaN();
      expect_same(edited, "apparent_volume[5]");
    }
    // A copy carries the state of its values, not the original's later edits.
    FlowNetwork copy = net;
    net.mutable_pipe_conductance()[1] = -1.0;
    expect_same(net, "pipe_conductance");
    expect_same(copy, "");
  }
  omp_set_num_threads(before);
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

TEST(FlowNetwork, VolumeWeightedMeanPressureWeighsByTheChosenVolume) {
  FlowNetworkData d;
  testing::AddDomain(d, /*apparent=*/4.0, /*pore=*/3.0, /*pressure=*/10.0);
  testing::AddDomain(d, /*apparent=*/12.0, /*pore=*/1.0, /*pressure=*/20.0);
  testing::AddPipe(d, 0, 1, 1e-3, 1e-5, 1e-9);
  const FlowNetwork net = testing::MakeOrDie(d);
  EXPECT_DOUBLE_EQ(VolumeWeightedMeanPressure(net, StorageVolume::kApparent), 17.5);  // 280/16
  EXPECT_DOUBLE_EQ(VolumeWeightedMeanPressure(net, StorageVolume::kPore), 12.5);      // 50/4
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
  // Dirichlet left/right columns, no flow top/bottom: k = a^3/(24 R) (docs/physics.md §1.3).
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

// kAuto (the choice a scene makes with solver.linear_solver AUTO): Eigen's simplicial LDL^T
// below kSupernodalMinUnknowns unknowns, CHOLMOD supernodal from there on, and then the very
// bits of the solver it chose.
TEST(FlowNetwork, AutoLinearSolverIsSimplicialBelowTheSwitchAndSupernodalFromIt) {
  EXPECT_EQ(ResolvedLinearSolverKind(LinearSolverKind::kAuto, kSupernodalMinUnknowns - 1),
            LinearSolverKind::kEigenSimplicialLdlt);
  EXPECT_EQ(ResolvedLinearSolverKind(LinearSolverKind::kAuto, kSupernodalMinUnknowns),
            LinearSolverKind::kCholmodSupernodal);
  EXPECT_EQ(ResolvedLinearSolverKind(LinearSolverKind::kCholmodSupernodal, 1),
            LinearSolverKind::kCholmodSupernodal);
  EXPECT_EQ(ResolvedLinearSolverKind(LinearSolverKind::kEigenSimplicialLdlt, 1 << 30),
            LinearSolverKind::kEigenSimplicialLdlt);

  struct Run {
    LinearSolverKind in_use;
    std::vector<double> pressure;
  };
  const auto run = [](FlowNetwork net, LinearSolverKind kind) {
    ImplicitSolverOptions opt;
    opt.linear_solver = kind;
    auto solver = ImplicitSolver::Create(opt);
    EXPECT_TRUE(solver.ok());
    for (int s = 0; s < 3; ++s) EXPECT_TRUE(solver->Step(net, 1e-6).ok());
    return Run{solver->linear_solver_in_use(),
               std::vector<double>(net.pressure().begin(), net.pressure().end())};
  };
  // Below the switch: kSupernodalMinUnknowns - 1 unknowns of a random network.
  const int small_domains = static_cast<int>(kSupernodalMinUnknowns);
  FlowNetworkData small = testing::MakeRandomClosedData(small_domains, 4 * small_domains / 3, 7);
  small.role[0] = DomainRole::kFixedPressure;
  const Run auto_small = run(testing::MakeOrDie(small), LinearSolverKind::kAuto);
  const Run simplicial = run(testing::MakeOrDie(small), LinearSolverKind::kEigenSimplicialLdlt);
  EXPECT_EQ(auto_small.in_use, LinearSolverKind::kEigenSimplicialLdlt);
  EXPECT_EQ(auto_small.pressure, simplicial.pressure);
  // At the switch: a chain whose two ends are fixed, kSupernodalMinUnknowns unknowns between.
  const LatticeParams lp;
  const auto chain = [&] {
    return testing::MakeChain(static_cast<int>(kSupernodalMinUnknowns) + 1, lp,
                              lp.SquareApparentVolume(), lp.SquarePoreVolume(), false, 1e5);
  };
  const Run auto_large = run(chain(), LinearSolverKind::kAuto);
  const Run supernodal = run(chain(), LinearSolverKind::kCholmodSupernodal);
  EXPECT_EQ(auto_large.in_use, LinearSolverKind::kCholmodSupernodal);
  EXPECT_EQ(auto_large.pressure, supernodal.pressure);
}

// The explicit solver's limit on `net` is `reference` to the bit and the domain, on each of
// `thread_counts` (K_f = 2e9, default storage).
void ExpectSolverLimitIs(const FlowNetwork& net, const CriticalTimeStep& reference,
                         std::initializer_list<int> thread_counts) {
  const int before = omp_get_max_threads();
  for (const int threads : thread_counts) {
    omp_set_num_threads(threads);
    ExplicitSolverOptions options;
    options.bulk_modulus = 2e9;
    auto solver = ExplicitSolver::Create(options);
    ASSERT_TRUE(solver.ok());
    const auto limit = solver->CriticalStep(net);
    ASSERT_TRUE(limit.ok()) << limit.status().ToString();
    EXPECT_EQ(limit->dt_crit, reference.dt_crit) << threads << " thread(s)";
    EXPECT_EQ(limit->limiting_domain, reference.limiting_domain) << threads << " thread(s)";
    EXPECT_EQ(limit->limiting_storage_volume, reference.limiting_storage_volume);
    EXPECT_EQ(limit->limiting_conductance_sum, reference.limiting_conductance_sum);
  }
  omp_set_num_threads(before);
}

// The explicit solver's limit, found per domain on the threads (over 8192 domains: the parallel
// path), is the reference's: the least V_s/(K_f sum C) at the lowest domain index among ties. A
// uniform lattice ties every interior domain, so a combine that took any but the first share's
// least would name another domain.
TEST(FlowNetwork, ExplicitLimitOnThreadsIsTheReferencesLowestIndexOnTies) {
  const LatticeParams lp;
  FlowNetworkData d = testing::MakeSquareLatticeData(100, 100, lp);
  d.role[0] = DomainRole::kFixedPressure;
  const FlowNetwork net = testing::MakeOrDie(d);
  ASSERT_GT(net.num_domains(), 8192u);
  const auto reference = ComputeCriticalTimeStep(net, 2e9, StorageModel{});
  ASSERT_TRUE(reference.ok());
  ExpectSolverLimitIs(net, *reference, {1, 2});
}

// The limit search divides only where a multiplication cannot rule a domain out: on random
// networks (and with a second domain 1 ulp above the least, and one exactly tied after it) the
// limit is still the reference's division by division, to the bit and the domain.
TEST(FlowNetwork, ExplicitLimitSkipsNoCandidateOnRandomNetworks) {
  const LatticeParams lp;
  for (const std::uint64_t seed : {1u, 2u, 3u, 4u, 5u}) {
    SCOPED_TRACE("seed " + std::to_string(seed));
    FlowNetworkData d = testing::MakeSquareLatticeData(100, 100, lp);
    std::mt19937_64 rng(seed);
    std::uniform_real_distribution<double> factor(0.2, 5.0);
    for (double& c : d.pipe_conductance) c *= factor(rng);
    for (std::size_t k = 0; k < d.pore_volume.size(); ++k) {
      d.pore_volume[k] *= factor(rng);
      d.apparent_volume[k] = std::max(d.apparent_volume[k], d.pore_volume[k]);
    }
    d.role[0] = DomainRole::kFixedPressure;
    FlowNetwork net = testing::MakeOrDie(d);
    const auto first = ComputeCriticalTimeStep(net, 2e9, StorageModel{});
    ASSERT_TRUE(first.ok());
    // Domains after the least with a limit 1 ulp above it and exactly equal to it: neither may
    // win (the lowest index wins ties); then, further on, one 1 ulp below it, which must.
    const auto k = static_cast<std::size_t>(first->limiting_domain);
    ASSERT_LT(k + 13, net.num_domains());
    for (const std::size_t other : {k + 7, k + 11, k + 13}) {
      const double target = other == k + 7    ? std::nextafter(first->dt_crit, 1.0)
                            : other == k + 11 ? first->dt_crit
                                              : std::nextafter(first->dt_crit, 0.0);
      // V_s = dt K_f sum C for `other`, nudged until the division gives the target exactly.
      double sum = 0.0;
      for (std::size_t p = 0; p < net.num_pipes(); ++p) {
        if (static_cast<std::size_t>(net.pipe_domain_a()[p]) == other ||
            static_cast<std::size_t>(net.pipe_domain_b()[p]) == other) {
          sum += net.pipe_conductance()[p];
        }
      }
      double v = target * (2e9 * sum);
      for (int i = 0; i < 8 && v / (2e9 * sum) != target; ++i) {
        v = v / (2e9 * sum) < target ? std::nextafter(v, 1.0) : std::nextafter(v, 0.0);
      }
      ASSERT_EQ(v / (2e9 * sum), target);
      d.pore_volume[other] = v;
      d.apparent_volume[other] = std::max(d.apparent_volume[other], v);
    }
    net = testing::MakeOrDie(d);
    const auto reference = ComputeCriticalTimeStep(net, 2e9, StorageModel{});
    ASSERT_TRUE(reference.ok());
    ASSERT_EQ(reference->limiting_domain, static_cast<std::int32_t>(k + 13));
    ExpectSolverLimitIs(net, *reference, {1, 2, 3});
  }
}

// The explicit solver's per-domain sum of conductances is added pipe by pipe in pipe order; on
// threads each share of the domains takes the pipes touching it, in the same order. With uneven
// conductances and volumes (sums whose order shows in the bits), any thread count, and a solver
// whose thread count changes between steps, give the one-thread pressures bit for bit.
TEST(FlowNetwork, ExplicitStepsAreBitIdenticalOnAnyThreadCount) {
  const LatticeParams lp;
  FlowNetworkData d = testing::MakeSquareLatticeData(100, 100, lp);
  std::mt19937_64 rng(17);
  std::uniform_real_distribution<double> factor(0.3, 3.0);
  for (double& c : d.pipe_conductance) c *= factor(rng);
  for (std::size_t k = 0; k < d.pore_volume.size(); ++k) {
    d.pore_volume[k] *= factor(rng);
    d.pressure[k] = 1e5 * factor(rng);
  }
  d.role[0] = DomainRole::kFixedPressure;
  d.role[5000] = DomainRole::kFixedPressure;  // in the second share of two
  d.role[777] = DomainRole::kSource;
  d.source_rate[777] = 1e-9;
  ASSERT_GT(d.pore_volume.size(), 8192u);
  std::vector<double> dv(d.pore_volume.size());
  for (std::size_t k = 0; k < dv.size(); ++k) dv[k] = 1e-12 * std::sin(static_cast<double>(k));
  // Everything a step gives: the pressures, every budget figure of its report, the tally.
  struct Outcome {
    std::vector<double> pressure, budget;
    FluidTally tally;
  };
  const int before = omp_get_max_threads();
  const auto run = [&](std::initializer_list<int> thread_counts, bool diagnostics) {
    FlowNetwork net = testing::MakeOrDie(d);
    ExplicitSolverOptions options;
    options.bulk_modulus = 2e9;
    options.diagnostics = diagnostics;
    auto solver = ExplicitSolver::Create(options);
    EXPECT_TRUE(solver.ok());
    Outcome out;
    out.tally.Reset(net.num_domains());
    for (const int threads : thread_counts) {
      omp_set_num_threads(threads);
      const auto limit = solver->CriticalStep(net);
      EXPECT_TRUE(limit.ok());
      for (int k = 0; k < 5; ++k) {
        // Rigid steps and steps with a volume change, both.
        const auto r =
            solver->Step(net, 0.5 * limit->dt_crit, k % 2 == 0 ? std::span<const double>() : dv,
                         diagnostics ? &out.tally : nullptr);
        EXPECT_TRUE(r.ok());
        if (!r.ok()) continue;
        out.budget.insert(out.budget.end(),
                          {r->boundary_inflow, r->source_inflow, r->volume_change, r->stored_change,
                           r->mass_balance_error, r->min_pressure, r->max_pressure});
      }
      // A coefficient edit: the sums are refreshed on the next step.
      for (double& x : net.mutable_pipe_conductance()) x *= 1.01;
    }
    out.pressure.assign(net.pressure().begin(), net.pressure().end());
    return out;
  };
  const auto expect_same = [](const Outcome& got, const Outcome& want, const char* what) {
    SCOPED_TRACE(what);
    // Bits, not tolerances: NaN budgets (diagnostics off) compare as their bytes.
    const auto bits = [](const std::vector<double>& v) {
      std::vector<std::uint64_t> out(v.size());
      std::memcpy(out.data(), v.data(), v.size() * sizeof(double));
      return out;
    };
    EXPECT_EQ(got.pressure, want.pressure);
    EXPECT_EQ(bits(got.budget), bits(want.budget));
    EXPECT_EQ(got.tally.node_outflow_m2, want.tally.node_outflow_m2);
    EXPECT_EQ(std::vector<double>({got.tally.source_m2, got.tally.compressed_m2,
                                   got.tally.pore_growth_m2, got.tally.boundary_gross_m2}),
              std::vector<double>({want.tally.source_m2, want.tally.compressed_m2,
                                   want.tally.pore_growth_m2, want.tally.boundary_gross_m2}));
  };
  for (const bool diagnostics : {true, false}) {
    SCOPED_TRACE(diagnostics ? "diagnostics on" : "diagnostics off");
    const Outcome reference = run({1, 1, 1, 1}, diagnostics);
    // The fluid moved, through the fixed domains and from the source.
    ASSERT_NE(reference.pressure, d.pressure);
    if (diagnostics) {
      EXPECT_NE(reference.tally.node_outflow_m2[5000], 0.0);
      EXPECT_GT(reference.tally.source_m2, 0.0);
    }
    expect_same(run({2, 2, 2, 2}, diagnostics), reference, "2 threads");
    expect_same(run({3, 3, 3, 3}, diagnostics), reference, "3 threads");
    expect_same(run({1, 2, 3, 2}, diagnostics), reference, "changing counts");
    // Asked for 3 threads, given a team of 1 (no active parallel level): one thread takes every
    // share in turn.
    const int levels = omp_get_max_active_levels();
    omp_set_max_active_levels(0);
    expect_same(run({3, 3, 3, 3}, diagnostics), reference, "a team of 1");
    omp_set_max_active_levels(levels);
  }
  omp_set_num_threads(before);
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

// The storage-volume span of `storage` (a coefficient edit: bumps the coefficient stamp).
std::span<double> MutableStorageVolume(FlowNetwork& net, StorageVolume storage) {
  return storage == StorageVolume::kPore ? net.mutable_pore_volume()
                                         : net.mutable_apparent_volume();
}

std::vector<double> Pressures(const FlowNetwork& net) {
  return std::vector<double>(net.pressure().begin(), net.pressure().end());
}

// A random closed network with domain 0 held fixed and `source` injecting 1e-9 m^2/s.
FlowNetwork FixedAndSourceNetwork(int n, int extra_pipes, std::uint64_t seed, std::size_t source) {
  FlowNetworkData d = testing::MakeRandomClosedData(n, extra_pipes, seed);
  d.role[0] = DomainRole::kFixedPressure;
  d.role[source] = DomainRole::kSource;
  d.source_rate[source] = 1e-9;
  return testing::MakeOrDie(d);
}

// A long-lived explicit solver takes a coefficient edit (the coupled loop moves volumes and
// apertures at every flow update) through RefreshCoefficients without re-validating the
// topology; a solver created afresh on a copy of the edited network, as after a resume from a
// checkpoint, validates it whole. Both must step to the same bits, or a resumed run drifts from
// the uninterrupted one. Each round edits another kind of coefficient (storage volumes, every
// aperture, two conductances, a source rate), then takes three steps on both; an unedited copy
// stepped alongside shows that every edit changes the pressures (so the comparison can fail).
TEST(FlowNetwork, ExplicitCoefficientEditStepsBitIdenticalToAFreshSolver) {
  for (const StorageVolume storage : {StorageVolume::kPore, StorageVolume::kApparent}) {
    SCOPED_TRACE(std::string(StorageVolumeName(storage)));
    FlowNetwork net = FixedAndSourceNetwork(80, 60, 11, 40);
    ExplicitSolverOptions options;
    options.storage = {storage, 1.3};
    auto long_lived = ExplicitSolver::Create(options);
    ASSERT_TRUE(long_lived.ok());
    const auto limit = ComputeCriticalTimeStep(net, options.bulk_modulus, options.storage);
    ASSERT_TRUE(long_lived->Step(net, 0.5 * limit->dt_crit).ok());  // topology known from here
    const std::uint64_t topology = net.topology_version();

    for (int round = 0; round < 4; ++round) {
      SCOPED_TRACE("round " + std::to_string(round));
      FlowNetwork unedited = net;
      switch (round) {
        case 0: {  // storage volumes, both ways (V_p <= V_d = 2 V_p holds either way)
          std::span<double> v = MutableStorageVolume(net, storage);
          v[5] *= 0.6;
          v[17] *= 1.7;
          break;
        }
        case 1: {  // every aperture, hence every conductance
          std::vector<double> a(net.pipe_aperture().begin(), net.pipe_aperture().end());
          for (std::size_t p = 0; p < a.size(); ++p)
            a[p] *= 1.0 + 0.01 * static_cast<double>(p % 7);
          ASSERT_TRUE(net.SetApertures(a, 1e-3).ok());
          break;
        }
        case 2: {
          std::span<double> c = net.mutable_pipe_conductance();
          c[3] *= 4.0;
          c[30] *= 0.25;
          break;
        }
        case 3:  // a new rate on a source domain: a value edit, not a role edit
          ASSERT_TRUE(net.SetSource(40, 3e-9).ok());
          break;
      }
      ASSERT_EQ(net.topology_version(), topology) << "the edits must not change the topology";
      FlowNetwork resumed = net;
      auto fresh = ExplicitSolver::Create(options);
      auto stale = ExplicitSolver::Create(options);
      ASSERT_TRUE(fresh.ok() && stale.ok());
      // Within the limit of both the edited and the unedited network.
      const double dt =
          0.5 *
          std::min(
              ComputeCriticalTimeStep(net, options.bulk_modulus, options.storage)->dt_crit,
              ComputeCriticalTimeStep(unedited, options.bulk_modulus, options.storage)->dt_crit);
      for (int s = 0; s < 3; ++s) {
        const auto a = long_lived->Step(net, dt);
        const auto b = fresh->Step(resumed, dt);
        ASSERT_TRUE(a.ok()) << a.status().ToString();
        ASSERT_TRUE(b.ok()) << b.status().ToString();
        ASSERT_TRUE(stale->Step(unedited, dt).ok());
        EXPECT_EQ(a->dt_crit, b->dt_crit);
        EXPECT_EQ(a->limiting_domain, b->limiting_domain);
        for (std::size_t i = 0; i < net.num_domains(); ++i) {
          EXPECT_EQ(net.pressure()[i], resumed.pressure()[i]) << "domain " << i << ", step " << s;
        }
      }
      EXPECT_NE(Pressures(net), Pressures(unedited)) << "the edit must matter";
    }
  }
}

// A coefficient edit is checked where the refresh reads it, before any pressure is written: a
// free domain whose storage volume became 0 (its update would divide by zero) and a NaN
// conductance are refused naming the field and index, with the same message a fresh solver gives
// on the edited network; once the value is restored the same solver steps again.
TEST(FlowNetwork, ExplicitCoefficientEditIsCheckedBeforeAnyPressureIsWritten) {
  for (const StorageVolume storage : {StorageVolume::kPore, StorageVolume::kApparent}) {
    const std::string field = storage == StorageVolume::kPore ? "pore_volume" : "apparent_volume";
    SCOPED_TRACE(field);
    FlowNetworkData d = testing::MakeRandomClosedData(30, 20, 5);
    d.role[0] = DomainRole::kFixedPressure;
    FlowNetwork net = testing::MakeOrDie(d);
    ExplicitSolverOptions options;
    options.storage.volume = storage;
    auto solver = ExplicitSolver::Create(options);
    ASSERT_TRUE(solver.ok());
    const double dt = 0.5 * solver->CriticalStep(net)->dt_crit;
    ASSERT_TRUE(solver->Step(net, dt).ok());
    const std::vector<double> before = Pressures(net);

    // Domain 12 collapses: V_p = V_d = 0 (a valid network, but not for a free domain's update).
    const double kept_pore = net.pore_volume()[12], kept_apparent = net.apparent_volume()[12];
    net.mutable_pore_volume()[12] = 0.0;
    net.mutable_apparent_volume()[12] = 0.0;
    const auto refused = solver->Step(net, dt);
    EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(refused.status().message().rfind("flow.network." + field + "[12]: ", 0), 0u)
        << refused.status().message();
    EXPECT_EQ(Pressures(net), before);
    FlowNetwork copy = net;
    auto fresh = ExplicitSolver::Create(options);
    ASSERT_TRUE(fresh.ok());
    EXPECT_EQ(fresh->Step(copy, dt).status().message(), refused.status().message());
    net.mutable_pore_volume()[12] = kept_pore;
    net.mutable_apparent_volume()[12] = kept_apparent;
    ASSERT_TRUE(solver->Step(net, dt).ok());
    EXPECT_NE(Pressures(net), before);

    const std::vector<double> before_nan = Pressures(net);
    const double kept_c = net.pipe_conductance()[7];
    net.mutable_pipe_conductance()[7] = std::numeric_limits<double>::quiet_NaN();
    const auto nan = solver->Step(net, dt);
    EXPECT_EQ(nan.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(nan.status().message().rfind("flow.network.pipe_conductance[7]: ", 0), 0u)
        << nan.status().message();
    EXPECT_EQ(Pressures(net), before_nan);
    net.mutable_pipe_conductance()[7] = kept_c;
    EXPECT_TRUE(solver->Step(net, dt).ok());
  }
}

// A refused coefficient edit leaves nothing trusted behind: a copy of the network taken before
// the edit (its stamps are the pre-edit ones) then steps, and reports its limit, exactly as with
// a fresh solver. And the long-lived solver refuses what a fresh one refuses, also for values it
// does not read (pore_volume above apparent_volume with apparent storage, a negative volume).
TEST(FlowNetwork, ExplicitRefusedEditLeavesNoHalfRefreshedCache) {
  FlowNetwork net = FixedAndSourceNetwork(30, 20, 5, 20);
  ExplicitSolverOptions options;
  auto solver = ExplicitSolver::Create(options);
  ASSERT_TRUE(solver.ok());
  const double dt = 0.5 * solver->CriticalStep(net)->dt_crit;
  ASSERT_TRUE(solver->Step(net, dt).ok());
  FlowNetwork backup = net;
  net.mutable_pore_volume()[1] = 0.0;
  ASSERT_FALSE(solver->Step(net, dt).ok());
  auto fresh = ExplicitSolver::Create(options);
  ASSERT_TRUE(fresh.ok());
  FlowNetwork twin = backup;
  const auto limit = solver->CriticalStep(backup);
  ASSERT_TRUE(limit.ok());
  EXPECT_EQ(limit->dt_crit, fresh->CriticalStep(twin)->dt_crit);
  EXPECT_EQ(limit->limiting_domain, fresh->CriticalStep(twin)->limiting_domain);
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(solver->Step(backup, dt).ok());
    ASSERT_TRUE(fresh->Step(twin, dt).ok());
  }
  EXPECT_EQ(Pressures(backup), Pressures(twin));
  EXPECT_EQ(solver->Step(backup, 100.0 * limit->dt_crit).status().code(),
            StatusCode::kFailedPrecondition);

  for (const auto& [field, value] :
       {std::pair<std::string, double>{"pore_volume[3]", 3.0 * backup.apparent_volume()[3]},
        std::pair<std::string, double>{"apparent_volume[4]", -1.0}}) {
    SCOPED_TRACE(field);
    FlowNetwork edited = backup;
    ASSERT_TRUE(solver->Step(edited, dt).ok());  // the solver knows this topology
    if (field.starts_with("pore")) {
      edited.mutable_pore_volume()[3] = value;
    } else {
      edited.mutable_apparent_volume()[4] = value;
    }
    FlowNetwork edited_twin = edited;
    auto another = ExplicitSolver::Create(options);
    ASSERT_TRUE(another.ok());
    const auto kept = solver->Step(edited, dt);
    const auto refused = another->Step(edited_twin, dt);
    EXPECT_EQ(kept.status().code(), StatusCode::kInvalidArgument);
    EXPECT_EQ(kept.status().message(), refused.status().message());
    EXPECT_NE(kept.status().message().find(field), std::string::npos) << kept.status().message();
  }
}

// The implicit solver's counterpart: an edit refused while its caches were being refreshed (a
// free domain's pore volume set to 0 passes the network's checks and fails only the storage
// capacities, after those of the lower domains were overwritten) leaves nothing trusted behind. A
// copy taken before the edit then steps to the bits of a fresh solver on another copy, and a long-
// lived solver takes a later coefficient edit as a fresh one does.
TEST(FlowNetwork, ImplicitRefusedEditLeavesNoHalfRefreshedCache) {
  FlowNetwork net = FixedAndSourceNetwork(30, 20, 5, 20);
  const double dt =
      50.0 * ComputeCriticalTimeStep(net, ImplicitSolverOptions{}.bulk_modulus, {})->dt_crit;
  auto solver = ImplicitSolver::Create({});
  ASSERT_TRUE(solver.ok());
  ASSERT_TRUE(solver->Step(net, dt).ok());
  FlowNetwork backup = net;
  net.mutable_pore_volume()[25] = 0.0;
  const auto refused = solver->Step(net, dt);
  EXPECT_EQ(refused.status().code(), StatusCode::kInvalidArgument);
  EXPECT_EQ(refused.status().message().rfind("flow.network.pore_volume[25]: ", 0), 0u)
      << refused.status().message();
  auto fresh = ImplicitSolver::Create({});
  ASSERT_TRUE(fresh.ok());
  FlowNetwork twin = backup;
  for (int k = 0; k < 3; ++k) {
    ASSERT_TRUE(solver->Step(backup, dt).ok());
    ASSERT_TRUE(fresh->Step(twin, dt).ok());
  }
  EXPECT_EQ(Pressures(backup), Pressures(twin));

  // A known topology, new volumes and conductances: the same bits as a solver created afresh.
  for (double& v : backup.mutable_pore_volume()) v *= 1.1;
  for (double& c : backup.mutable_pipe_conductance()) c *= 0.9;
  FlowNetwork edited_twin = backup;
  auto another = ImplicitSolver::Create({});
  ASSERT_TRUE(another.ok());
  ASSERT_TRUE(solver->Step(backup, dt).ok());
  ASSERT_TRUE(another->Step(edited_twin, dt).ok());
  ASSERT_TRUE(fresh->Step(twin, dt).ok());
  EXPECT_EQ(Pressures(backup), Pressures(edited_twin));
  EXPECT_NE(Pressures(backup), Pressures(twin));  // the edit mattered
}

// After coefficient edits the solver's cached limit is ComputeCriticalTimeStep's, field by field
// and to the bit, so the governor refuses exactly the steps the documented formula forbids. On a
// square lattice with a Dirichlet left column every interior domain ties (same V_s, four equal
// pipes): the lowest index wins, domain 9, until a shrunken domain takes over and after its
// volume is restored the tie goes back to 9.
TEST(FlowNetwork, ExplicitCriticalStepAfterCoefficientEditsIsTheFormulas) {
  const LatticeParams lp;
  for (const StorageVolume storage : {StorageVolume::kPore, StorageVolume::kApparent}) {
    SCOPED_TRACE(std::string(StorageVolumeName(storage)));
    FlowNetworkData d = testing::MakeSquareLatticeData(8, 6, lp);
    for (int j = 0; j < 6; ++j) {
      d.role[static_cast<std::size_t>(j * 8)] = DomainRole::kFixedPressure;
      d.pressure[static_cast<std::size_t>(j * 8)] = 1e5;
    }
    FlowNetwork net = testing::MakeOrDie(d);
    ExplicitSolverOptions options;
    options.bulk_modulus = lp.bulk_modulus;
    options.storage = {storage, 0.7};
    auto solver = ExplicitSolver::Create(options);
    ASSERT_TRUE(solver.ok());
    auto expect_formula = [&](const char* what, std::int32_t limiting) {
      SCOPED_TRACE(what);
      const auto got = solver->CriticalStep(net);
      const auto want = ComputeCriticalTimeStep(net, options.bulk_modulus, options.storage);
      ASSERT_TRUE(got.ok()) << got.status().ToString();
      ASSERT_TRUE(want.ok());
      EXPECT_EQ(got->dt_crit, want->dt_crit);
      EXPECT_EQ(got->limiting_domain, want->limiting_domain);
      EXPECT_EQ(got->limiting_storage_volume, want->limiting_storage_volume);
      EXPECT_EQ(got->limiting_conductance_sum, want->limiting_conductance_sum);
      EXPECT_EQ(want->limiting_domain, limiting);
      // The governor: safety * dt_crit is allowed, one ulp more is refused.
      const double allowed = options.safety_factor * want->dt_crit;
      EXPECT_EQ(solver->Step(net, std::nextafter(allowed, 1.0)).status().code(),
                StatusCode::kFailedPrecondition);
      EXPECT_TRUE(solver->Step(net, allowed).ok());
    };
    expect_formula("as built", 9);
    const double kept =
        (storage == StorageVolume::kPore ? net.pore_volume() : net.apparent_volume())[30];
    MutableStorageVolume(net, storage)[30] = 0.25 * kept;
    expect_formula("domain 30 shrunk", 30);
    std::vector<double> a(net.num_pipes(), lp.Aperture());
    a[0] = 1.2 * lp.Aperture();  // domains 0 (fixed) and 1 (an edge domain, 3 pipes)
    ASSERT_TRUE(net.SetApertures(a, lp.viscosity).ok());
    expect_formula("apertures set", 30);
    net.mutable_pipe_conductance()[0] *= 40.0;  // domain 1 now drains fastest
    expect_formula("one conductance raised", 1);
    net.mutable_pipe_conductance()[0] = lp.Conductance();
    MutableStorageVolume(net, storage)[30] = kept;
    expect_formula("restored", 9);
  }
}

}  // namespace
}  // namespace seep::core
