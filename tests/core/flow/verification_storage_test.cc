// V09 storage choice: with V_s = V_d instead of V_p every transient is slower by V_d/V_p = 1/n_s
// (docs/physics.md §1.2, §3.2): 4/(4 - pi) = 4.66 on square cells, sqrt3/(sqrt3 - pi/2) = 10.7 on
// hex.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "flow_test_networks.h"
#include "seep/core/flow/explicit_solver.h"

namespace seep::core {
namespace {

using testing::LatticeParams;

// Time at which domain `probe` first reaches `threshold`, linearly interpolated between steps.
double ArrivalTime(const FlowNetworkData& data, StorageVolume storage, double dt, int probe,
                   double threshold) {
  const LatticeParams lp;
  FlowNetwork net = testing::MakeOrDie(data);
  const int mx = 12, my = 4;
  for (int j = 0; j < my; ++j) EXPECT_TRUE(net.SetFixedPressure(j * mx, 1.0).ok());
  ExplicitSolverOptions opt;
  opt.bulk_modulus = lp.bulk_modulus;
  opt.storage.volume = storage;
  opt.diagnostics = false;
  auto solver = ExplicitSolver::Create(opt);
  EXPECT_TRUE(solver.ok());
  double t = 0.0;
  double before = net.pressure()[probe];
  for (int step = 0; step < 10000000; ++step) {
    EXPECT_TRUE(solver->Step(net, dt).ok());
    const double after = net.pressure()[probe];
    if (after >= threshold) return t + dt * (threshold - before) / (after - before);
    before = after;
    t += dt;
  }
  ADD_FAILURE() << "no arrival";
  return 0.0;
}

TEST(Verification, V09_StorageChoiceScalesArrivalTimes) {
  const LatticeParams lp;
  const double square_ratio = lp.SquareApparentVolume() / lp.SquarePoreVolume();
  const double hex_ratio = lp.HexApparentVolume() / lp.HexPoreVolume();
  EXPECT_NEAR(square_ratio, 4.0 / (4.0 - std::numbers::pi), 1e-14);
  EXPECT_NEAR(square_ratio, 4.66, 0.005);
  EXPECT_NEAR(hex_ratio, std::numbers::sqrt3 / (std::numbers::sqrt3 - std::numbers::pi / 2), 1e-13);
  EXPECT_NEAR(hex_ratio, 10.7, 0.05);

  const int mx = 12, my = 4;
  const int probe = 1 * mx + 8;  // row 1, column 8
  for (const bool hex : {false, true}) {
    const FlowNetworkData data =
        hex ? testing::MakeHoneycombData(mx, my, lp) : testing::MakeSquareLatticeData(mx, my, lp);
    // The same absolute dt for both storage choices, small against the pore-volume limit, so the
    // time discretisation barely differs between the runs.
    FlowNetwork probe_net = testing::MakeOrDie(data);
    ExplicitSolverOptions opt;
    opt.bulk_modulus = lp.bulk_modulus;
    auto limit = ExplicitSolver::Create(opt)->CriticalStep(probe_net);
    ASSERT_TRUE(limit.ok());
    const double dt = 0.01 * limit->dt_crit;
    const double t_pore = ArrivalTime(data, StorageVolume::kPore, dt, probe, 0.2);
    const double t_apparent = ArrivalTime(data, StorageVolume::kApparent, dt, probe, 0.2);
    const double expected = hex ? hex_ratio : square_ratio;
    EXPECT_NEAR(t_apparent / t_pore, expected, 1e-3 * expected) << (hex ? "hex" : "square");
  }
}

}  // namespace
}  // namespace seep::core
