// V01 two-domain relaxation and V02 mass conservation (docs/physics.md §5).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <vector>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/flow_diagnostics.h"
#include "seep/core/flow/implicit_solver.h"

namespace seep::core {
namespace {

using testing::AddDomain;
using testing::AddPipe;

constexpr double kV1 = 1e-7, kV2 = 3e-7, kC = 1e-9, kKf = 2e9;
constexpr double kP1 = 1e5, kP2 = 0.0;

FlowNetwork TwoDomains() {
  FlowNetworkData d;
  AddDomain(d, kV1, kV1, kP1);
  AddDomain(d, kV2, kV2, kP2);
  AddPipe(d, 0, 1, 1e-3, 1e-5, kC);
  return testing::MakeOrDie(d);
}

double Lambda() { return kKf * kC * (1.0 / kV1 + 1.0 / kV2); }

// P1 - P2 decays by rho per step while V1 P1 + V2 P2 is conserved.
void ExpectTwoDomainState(const FlowNetwork& net, double decay) {
  const double mean = (kV1 * kP1 + kV2 * kP2) / (kV1 + kV2);
  const double diff = (kP1 - kP2) * decay;
  const double p1 = mean + kV2 / (kV1 + kV2) * diff;
  const double p2 = mean - kV1 / (kV1 + kV2) * diff;
  EXPECT_NEAR(net.pressure()[0] - net.pressure()[1], diff, 1e-12 * std::abs(diff));
  EXPECT_NEAR(net.pressure()[0], p1, 1e-12 * p1);
  EXPECT_NEAR(net.pressure()[1], p2, 1e-12 * p2);
}

TEST(Verification, V01_TwoDomainRelaxation) {
  const double lambda = Lambda();
  EXPECT_NEAR(lambda, 2.0e9 * 1e-9 * (1e7 + 1e7 / 3.0), 1e-6 * lambda);

  // Explicit: (1 - lambda dt)^n exactly.
  {
    FlowNetwork net = TwoDomains();
    ExplicitSolverOptions opt;
    opt.bulk_modulus = kKf;
    auto solver = ExplicitSolver::Create(opt);
    ASSERT_TRUE(solver.ok());
    const auto limit = solver->CriticalStep(net);
    ASSERT_TRUE(limit.ok());
    EXPECT_NEAR(limit->dt_crit, kV1 / (kKf * kC), 1e-15 * limit->dt_crit);  // domain 0 limits
    EXPECT_EQ(limit->limiting_domain, 0);
    const double dt = 0.05 * limit->dt_crit;
    const int n = 40;
    for (int s = 0; s < n; ++s) {
      const auto r = solver->Step(net, dt);
      ASSERT_TRUE(r.ok()) << r.status().ToString();
      EXPECT_EQ(r->dt, dt);
    }
    ExpectTwoDomainState(net, std::pow(1.0 - lambda * dt, n));
  }
  // Backward Euler: 1/(1 + lambda dt)^n exactly, at steps far beyond the explicit limit.
  for (const auto kind :
       {LinearSolverKind::kCholmodSupernodal, LinearSolverKind::kEigenSimplicialLdlt}) {
    FlowNetwork net = TwoDomains();
    ImplicitSolverOptions opt;
    opt.bulk_modulus = kKf;
    opt.linear_solver = kind;
    auto solver = ImplicitSolver::Create(opt);
    ASSERT_TRUE(solver.ok());
    const double dt = 0.3 / lambda;
    const int n = 25;
    for (int s = 0; s < n; ++s) ASSERT_TRUE(solver->Step(net, dt).ok());
    ExpectTwoDomainState(net, std::pow(1.0 / (1.0 + lambda * dt), n));
  }
  // Continuous limit: explicit converges to exp(-lambda t) at first order in dt; the error is
  // (lambda^2 dt t / 2) exp(-lambda t) to leading order.
  {
    const double t_end = 1.0 / lambda;
    double previous_error = 0.0;
    for (const int n : {1000, 2000, 4000}) {
      FlowNetwork net = TwoDomains();
      ExplicitSolverOptions opt;
      opt.bulk_modulus = kKf;
      auto solver = ExplicitSolver::Create(opt);
      ASSERT_TRUE(solver.ok());
      const double dt = t_end / n;
      for (int s = 0; s < n; ++s) ASSERT_TRUE(solver->Step(net, dt).ok());
      const double ratio = (net.pressure()[0] - net.pressure()[1]) / (kP1 - kP2);
      const double exact = std::exp(-lambda * t_end);
      const double error = exact - ratio;
      const double leading = lambda * lambda * dt * t_end / 2.0 * exact;
      EXPECT_NEAR(error, leading, 0.01 * leading) << "n = " << n;
      if (previous_error > 0.0) {
        EXPECT_NEAR(previous_error / error, 2.0, 0.01);
      }
      previous_error = error;
    }
  }
  // The explicit scheme is unstable above 2/lambda; the governor stops well before that.
  {
    FlowNetwork net = TwoDomains();
    ExplicitSolverOptions opt;
    opt.bulk_modulus = kKf;
    auto refusing = ExplicitSolver::Create(opt);
    ASSERT_TRUE(refusing.ok());
    const double dt_crit = refusing->CriticalStep(net)->dt_crit;
    EXPECT_LT(dt_crit, 2.0 / lambda);
    const double dt_unstable = 2.2 / lambda;
    const auto refused = refusing->Step(net, dt_unstable);
    EXPECT_EQ(refused.status().code(), StatusCode::kFailedPrecondition);
    EXPECT_NE(refused.status().message().find("at domain 0"), std::string::npos)
        << refused.status().message();
    EXPECT_EQ(net.pressure()[0], kP1);  // untouched

    opt.policy = StepLimitPolicy::kReduce;
    auto reducing = ExplicitSolver::Create(opt);
    ASSERT_TRUE(reducing.ok());
    const auto reduced = reducing->Step(net, dt_unstable);
    ASSERT_TRUE(reduced.ok());
    EXPECT_EQ(reduced->dt, opt.safety_factor * dt_crit);
    EXPECT_EQ(reduced->dt_requested, dt_unstable);

    // What the governor prevents: advise-only at 2.2/lambda grows like |1 - 2.2|^n.
    FlowNetwork wild = TwoDomains();
    opt.policy = StepLimitPolicy::kAdviseOnly;
    auto advising = ExplicitSolver::Create(opt);
    ASSERT_TRUE(advising.ok());
    for (int s = 0; s < 30; ++s) {
      const auto r = advising->Step(wild, dt_unstable);
      ASSERT_TRUE(r.ok());
      EXPECT_TRUE(r->limit_exceeded);
    }
    const double growth = (wild.pressure()[0] - wild.pressure()[1]) / (kP1 - kP2);
    EXPECT_NEAR(growth, std::pow(1.0 - lambda * dt_unstable, 30), 1e-9 * std::pow(1.2, 30));
    EXPECT_GT(std::abs(growth), 100.0);
  }
}

// Sum over non-fixed domains of V_s P / K_f, summed independently of the solvers.
double StoredExcess(const FlowNetwork& net, double kf) {
  double s = 0.0;
  for (std::size_t d = 0; d < net.num_domains(); ++d) {
    if (net.role()[d] != DomainRole::kFixedPressure) s += net.pore_volume()[d] * net.pressure()[d];
  }
  return s / kf;
}

TEST(Verification, V02_MassConservationOnRandomClosedNetwork) {
  const FlowNetworkData base = testing::MakeRandomClosedData(200, 250, 20240501);
  // Rigid, no sources: sum V_s P is constant.
  {
    FlowNetwork net = testing::MakeOrDie(base);
    const double initial = StoredExcess(net, kKf);
    ExplicitSolverOptions opt;
    opt.bulk_modulus = kKf;
    auto ex = ExplicitSolver::Create(opt);
    ASSERT_TRUE(ex.ok());
    const double dt = 0.9 * ex->CriticalStep(net)->dt_crit;
    for (int s = 0; s < 200; ++s) {
      const auto r = ex->Step(net, dt);
      ASSERT_TRUE(r.ok());
      EXPECT_LT(r->mass_balance_error, 1e-12);
    }
    EXPECT_NEAR(StoredExcess(net, kKf), initial, 1e-12 * initial);

    ImplicitSolverOptions iopt;
    iopt.bulk_modulus = kKf;
    auto be = ImplicitSolver::Create(iopt);
    ASSERT_TRUE(be.ok());
    for (int s = 0; s < 20; ++s) {
      const auto r = be->Step(net, 50.0 * dt);
      ASSERT_TRUE(r.ok());
      EXPECT_LT(r->mass_balance_error, 1e-12);
    }
    EXPECT_NEAR(StoredExcess(net, kKf), initial, 1e-12 * initial);
  }
  // Deforming, with sources: per step sum_i [V_s dP_i / K_f + dV_i] = sum Q_src dt.
  {
    FlowNetwork net = testing::MakeOrDie(base);
    ASSERT_TRUE(net.SetSource(3, 2e-7).ok());
    ASSERT_TRUE(net.SetSource(150, -5e-8).ok());
    std::mt19937_64 rng(99);
    std::uniform_real_distribution<double> unit(-1.0, 1.0);
    std::vector<double> dv(net.num_domains());
    for (double& v : dv) v = 1e-12 * unit(rng);  // a few 1e-5 of V_s per step
    const double q_total = 2e-7 - 5e-8;
    const double dv_total = std::accumulate(dv.begin(), dv.end(), 0.0);

    ExplicitSolverOptions opt;
    opt.bulk_modulus = kKf;
    auto ex = ExplicitSolver::Create(opt);
    ASSERT_TRUE(ex.ok());
    const double dt = 0.9 * ex->CriticalStep(net)->dt_crit;
    ImplicitSolverOptions iopt;
    iopt.bulk_modulus = kKf;
    auto be = ImplicitSolver::Create(iopt);
    ASSERT_TRUE(be.ok());
    for (int s = 0; s < 60; ++s) {
      const bool use_explicit = s % 2 == 0;
      const double step = use_explicit ? dt : 20.0 * dt;
      const double before = StoredExcess(net, kKf);
      const auto r = use_explicit ? ex->Step(net, step, dv) : be->Step(net, step, dv);
      ASSERT_TRUE(r.ok()) << r.status().ToString();
      const double after = StoredExcess(net, kKf);
      EXPECT_NEAR((after - before) + dv_total, q_total * step, 1e-12 * before) << "step " << s;
      EXPECT_LT(r->mass_balance_error, 1e-11);
      EXPECT_NEAR(r->source_inflow, q_total, 1e-15);
      EXPECT_NEAR(r->volume_change, dv_total, 1e-24);
    }
    // The proxy is the same sum plus the constant storage volume.
    const auto proxy = FluidMassProxy(net, kKf, {});
    ASSERT_TRUE(proxy.ok());
    double vs = 0.0;
    for (const double v : base.pore_volume) vs += v;
    EXPECT_NEAR(*proxy, vs + StoredExcess(net, kKf), 1e-14 * vs);
  }
}

}  // namespace
}  // namespace seep::core
