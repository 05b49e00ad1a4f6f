// V07 chain vs the exact discrete solution, V08 chain vs the continuum series (docs/physics.md
// §3.2, §5).
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <map>
#include <vector>

#include "chain_reference.h"
#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"

namespace seep::core {
namespace {

using testing::LatticeParams;
using testing::TimeScheme;

constexpr int kChainCells = 20;

FlowNetwork PoreChain(bool no_flow_end) {
  const LatticeParams lp;
  return testing::MakeChain(kChainCells, lp, lp.SquareApparentVolume(), lp.SquarePoreVolume(),
                            no_flow_end);
}

ExplicitSolver MakeExplicit(double kf) {
  ExplicitSolverOptions opt;
  opt.bulk_modulus = kf;
  opt.safety_factor = 1.0;
  auto s = ExplicitSolver::Create(opt);
  EXPECT_TRUE(s.ok());
  return std::move(s).value();
}

ImplicitSolver MakeImplicit(double kf) {
  ImplicitSolverOptions opt;
  opt.bulk_modulus = kf;
  auto s = ImplicitSolver::Create(opt);
  EXPECT_TRUE(s.ok());
  return std::move(s).value();
}

TEST(Verification, V07_ChainMatchesExactDiscreteSolution) {
  const LatticeParams lp;
  const double v = lp.SquarePoreVolume();
  const double c = lp.Conductance();
  const double kf = lp.bulk_modulus;
  {
    FlowNetwork net = PoreChain(false);
    ExplicitSolver solver = MakeExplicit(kf);
    const double dt = 0.9 * solver.CriticalStep(net)->dt_crit;
    for (int step = 1; step <= 500; ++step) {
      ASSERT_TRUE(solver.Step(net, dt).ok());
      if (step % 100 != 0) continue;
      for (int i = 1; i < kChainCells; ++i) {
        EXPECT_NEAR(
            net.pressure()[i],
            testing::ChainDiscreteExact(kChainCells, i, step, dt, kf, c, v, TimeScheme::kExplicit),
            1e-10)
            << "explicit, node " << i << ", step " << step;
      }
    }
  }
  {
    FlowNetwork net = PoreChain(false);
    ExplicitSolver probe = MakeExplicit(kf);
    const double dt = 10.0 * probe.CriticalStep(net)->dt_crit;
    ImplicitSolver solver = MakeImplicit(kf);
    for (int step = 1; step <= 50; ++step) {
      ASSERT_TRUE(solver.Step(net, dt).ok());
      if (step % 10 != 0) continue;
      for (int i = 1; i < kChainCells; ++i) {
        EXPECT_NEAR(net.pressure()[i],
                    testing::ChainDiscreteExact(kChainCells, i, step, dt, kf, c, v,
                                                TimeScheme::kBackwardEuler),
                    1e-10)
            << "BE, node " << i << ", step " << step;
      }
    }
  }
}

// Advances with `step(dt)` to each T (dimensionless, T = c t / L^2) and records the pressures.
std::map<double, std::vector<double>> RunToTimes(
    FlowNetwork& net, double dt, double time_scale, const std::vector<double>& Ts,
    const std::function<void(FlowNetwork&, double)>& step) {
  std::map<double, std::vector<double>> out;
  double t = 0.0;
  for (const double T : Ts) {
    const double t_end = T * time_scale;
    while (t < t_end * (1.0 - 1e-14)) {
      const double h = std::min(dt, t_end - t);
      step(net, h);
      t += h;
    }
    out[T] = std::vector<double>(net.pressure().begin(), net.pressure().end());
  }
  return out;
}

TEST(Verification, V08_ChainMatchesContinuumSeries) {
  const LatticeParams lp;
  const double h = 2.0 * lp.radius;
  const double v = lp.SquarePoreVolume();
  const double kf = lp.bulk_modulus;
  // Network diffusivity c = K_f C h^2 / V_s = k K_f / (mu n_s) (docs/physics.md §3.2).
  const double c = kf * lp.Conductance() * h * h / v;
  const double n_s = v / (4.0 * lp.radius * lp.radius);
  EXPECT_NEAR(c, lp.permeability * kf / (lp.viscosity * n_s), 1e-9 * c);
  // The series implementations reproduce the reference tables of docs/physics.md §3.2.
  EXPECT_NEAR(testing::SeriesDirichletDirichlet(0.5, 0.1), 0.26276, 5e-6);
  EXPECT_NEAR(testing::SeriesDirichletDirichlet(0.25, 0.02), 0.21130, 5e-6);
  EXPECT_NEAR(testing::SeriesDirichletNoFlow(0.75, 0.2), 0.28377, 5e-6);
  EXPECT_NEAR(testing::SeriesDirichletNoFlow(1.0, 0.5), 0.62922, 5e-6);

  const std::vector<double> Ts{0.02, 0.05, 0.1, 0.2, 0.5};
  const std::vector<int> nodes{kChainCells / 4, kChainCells / 2, 3 * kChainCells / 4};
  for (const bool no_flow : {false, true}) {
    // The no-flow wall sits half a cell beyond the last node: L_eff = (N + 1/2) h.
    const double length = no_flow ? (kChainCells + 0.5) * h : kChainCells * h;
    const double time_scale = length * length / c;
    auto series = [&](int i, double T) {
      const double xi = i * h / length;
      return no_flow ? testing::SeriesDirichletNoFlow(xi, T)
                     : testing::SeriesDirichletDirichlet(xi, T);
    };
    // Explicit at 0.9 dt_crit: spatial discretisation error only, <= 0.006 for T >= 0.02.
    {
      FlowNetwork net = PoreChain(no_flow);
      ExplicitSolver solver = MakeExplicit(kf);
      const double dt = 0.9 * solver.CriticalStep(net)->dt_crit;
      const auto out = RunToTimes(net, dt, time_scale, Ts, [&](FlowNetwork& n, double s) {
        ASSERT_TRUE(solver.Step(n, s).ok());
      });
      for (const double T : Ts) {
        for (const int i : nodes) {
          EXPECT_NEAR(out.at(T)[i], series(i, T), 0.006)
              << (no_flow ? "no-flow" : "Dirichlet") << " explicit T=" << T << " node " << i;
        }
      }
    }
    // Backward Euler: first order in time, <= 0.005 + 2.8 dt c / L^2 for T >= 0.05.
    for (const double factor : {2.0, 10.0}) {
      FlowNetwork net = PoreChain(no_flow);
      ExplicitSolver probe = MakeExplicit(kf);
      const double dt = factor * probe.CriticalStep(net)->dt_crit;
      ImplicitSolver solver = MakeImplicit(kf);
      const auto out = RunToTimes(net, dt, time_scale, Ts, [&](FlowNetwork& n, double s) {
        ASSERT_TRUE(solver.Step(n, s).ok());
      });
      const double tolerance = 0.005 + 2.8 * dt * c / (length * length);
      for (const double T : Ts) {
        if (T < 0.05) continue;
        for (const int i : nodes) {
          EXPECT_NEAR(out.at(T)[i], series(i, T), tolerance)
              << (no_flow ? "no-flow" : "Dirichlet") << " BE " << factor << " dt_crit, T=" << T
              << " node " << i;
        }
      }
    }
  }
}

}  // namespace
}  // namespace seep::core
