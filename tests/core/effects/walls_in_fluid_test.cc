// Walls in the fluid (physics.md §2.4 option B): the pores along walls are domains, the walls feel
// their pressure, the servo holds total stress, drained walls pass fluid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

#include "coupled_scenes.h"
#include "seep/core/run/simulation.h"

namespace seep::core {
namespace {

using effects_test::BoxedLatticeScene;
using effects_test::Contacts;
using effects_test::kRadius;

// A sealed box (every wall impermeable) of a 7 x 5 square... hex lattice at a uniform pressure P:
// every wall takes P over the span of the pores it closes, which for a box touching the lattice
// is its whole side, and the particles feel no net force at all.
SceneSpec SealedBox(double pressure) {
  SceneSpec s = BoxedLatticeScene(7, 6);
  s.boundary.initial_pressure_pa = pressure;
  WallsEffectSpec walls;
  walls.walls = {SideWall(WallSide::kBottom), SideWall(WallSide::kLeft), SideWall(WallSide::kRight),
                 SideWall(WallSide::kTop)};
  s.effects = {Contacts(), walls, FlowEffectSpec{}, FluidForcesEffectSpec{}};
  return s;
}

TEST(WallsInFluid, AUniformPressurePushesEachWallWithPressureTimesItsSide) {
  const double pressure = 3.7e4;
  Result<Simulation> created = Simulation::Create(SealedBox(pressure));
  ASSERT_TRUE(created.ok()) << created.status().message();
  Simulation& sim = *created;
  const LiveState& s = sim.stepper().state();
  // The initial forces are in after Create (the step's first force pass).
  ASSERT_EQ(s.wall_pore_force.size(), 4u);
  const auto [x_lo, x_hi] = std::minmax_element(s.particles.x.begin(), s.particles.x.end());
  const auto [y_lo, y_hi] = std::minmax_element(s.particles.y.begin(), s.particles.y.end());
  const double width = *x_hi - *x_lo + 2 * kRadius;
  const double height = *y_hi - *y_lo + 2 * kRadius;
  EXPECT_NEAR(s.wall_pore_force[0], pressure * width, 1e-9 * pressure * width);    // bottom
  EXPECT_NEAR(s.wall_pore_force[1], pressure * height, 1e-9 * pressure * height);  // left
  EXPECT_NEAR(s.wall_pore_force[2], pressure * height, 1e-9 * pressure * height);  // right
  EXPECT_NEAR(s.wall_pore_force[3], pressure * width, 1e-9 * pressure * width);    // top
}

}  // namespace
}  // namespace seep::core
