// The run's cumulative fluid books on a rigid transient permeameter (effects/fluid_ledger.h):
// they close to rounding under the explicit and the implicit solver, and the fluid they say
// the sample took up equals what its final pressures hold, sum V_s (P_end - P_0) / K_f — the
// state, not the increments the books added. The balance of a fracturing run, with its
// re-detections, is in tests/service/physics/fluid_books_test.cc.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scene_test_util.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/run/simulation.h"

namespace seep::core {
namespace {

using scene_test::Metric;

// 1e5 Pa held at the inlet of a square 31 x 4 lattice from t = 0, 0 at the outlet: the
// transient of examples/transient_1d.textproto, stopped half-way to the steady state.
SceneSpec FillingPermeameter(SolverKind kind) {
  SceneSpec s = scene_test::LatticeScene(LatticeKind::kSquare, 31, 4, FlowAxis::kX);
  s.fluid.bulk_modulus_pa = 2.2e9;
  s.solver.kind = kind;
  s.solver.storage = StorageVolume::kPore;
  s.solver.storage_factor = 0.37;  // any value in (0, 1]: the books weigh with the same V_s
  s.solver.dt_factor = kind == SolverKind::kExplicit ? 0.9 : 40.0;
  s.solver.end_time_s = 2e-3;
  return s;
}

void ExpectClosedBooks(SolverKind kind) {
  const SceneSpec scene = FillingPermeameter(kind);
  auto sim = Simulation::Create(scene);
  ASSERT_TRUE(sim.ok()) << sim.status().message();
  ASSERT_TRUE(sim->Run({}).ok());
  const RunReport report = sim->Report();
  const double in = -Metric(report, "fluid_left_inlet_m2");
  const double out = Metric(report, "fluid_left_outlet_m2");
  const double stored = Metric(report, "fluid_stored_m2");
  // From the state: the free domains' storage times their pressure rise (V_s is constant on a
  // rigid packing, so the level and the sum of the increments must agree).
  const FlowNetwork& flow = sim->network().flow;
  const StorageModel& storage = sim->stepper().state().storage;
  double held = 0.0;
  for (std::size_t d = 0; d < flow.num_domains(); ++d) {
    if (flow.role()[d] == DomainRole::kFixedPressure) continue;
    held += StorageVolumeOf(flow, storage, d) *
            (flow.pressure()[d] - scene.boundary.initial_pressure_pa) / scene.fluid.bulk_modulus_pa;
  }
  std::printf("books (%s): in %.17g out %.17g stored %.17g held %.17g, balance error %.3g\n",
              kind == SolverKind::kExplicit ? "explicit" : "implicit", in, out, stored, held,
              Metric(report, "fluid_balance_error"));
  // Half-way: fluid came in, about half of it left, half is held; none of them is trivial.
  EXPECT_GT(in, 0.0);
  EXPECT_GT(out, 0.25 * in);
  EXPECT_GT(stored, 0.25 * in);
  // Rounding of a sum over ~100 domains and a few thousand steps: far below 1e-12.
  EXPECT_LE(std::abs(in - out - stored), 1e-12 * in);
  EXPECT_LE(Metric(report, "fluid_balance_error"), 1e-12);
  EXPECT_NEAR(stored, held, 1e-12 * held);
  EXPECT_EQ(Metric(report, "fluid_injected_m2"), 0.0);
  EXPECT_EQ(Metric(report, "fluid_redetection_m2"), 0.0);
}

TEST(FluidBooks, ExplicitTransientClosesAndMatchesTheHeldFluid) {
  ExpectClosedBooks(SolverKind::kExplicit);
}

TEST(FluidBooks, ImplicitTransientClosesAndMatchesTheHeldFluid) {
  ExpectClosedBooks(SolverKind::kImplicit);
}

}  // namespace
}  // namespace seep::core
