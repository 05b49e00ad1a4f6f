// Walls in the fluid (docs/physics.md §2.4 option B): the pores along walls are domains, the walls
// feel their pressure, the servo holds total stress, drained walls pass fluid.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "coupled_scenes.h"
#include "seep/core/run/simulation.h"

namespace seep::core {
namespace {

using effects_test::BoxedLatticeScene;
using effects_test::Contacts;
using effects_test::kRadius;

// A sealed box (every wall impermeable) of a 7 x 6 hex lattice at a uniform pressure P: every
// wall takes P over the span of the pores it closes, which for a box touching the lattice is its
// whole side.
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

using effects_test::WithOpenEnds;

// BoxedLatticeScene lists the walls second; its left wall (walls[1]) is drained.
WallSpec& LeftWall(SceneSpec& scene) {
  return std::get<WallsEffectSpec>(scene.effects[1]).walls[1];
}

// The scene is refused as InvalidArgument with a message that starts with `prefix`.
void ExpectRefused(const SceneSpec& scene, const std::string& prefix) {
  const Status status = ValidateScene(scene);
  EXPECT_EQ(status.code(), StatusCode::kInvalidArgument) << status.message();
  EXPECT_EQ(status.message().rfind(prefix, 0), 0u) << status.message();
}

TEST(WallsInFluid, BadDrainsAndAWallsOnlyBoundaryWithoutWallsAreNamed) {
  SceneSpec scene = BoxedLatticeScene(6, 6);
  ASSERT_TRUE(ValidateScene(scene).ok());

  LeftWall(scene).drain->pressure_pa = std::numeric_limits<double>::quiet_NaN();
  ExpectRefused(scene,
                "scene.effects[1].walls.walls[1].drain.pressure_pa: a drained wall needs a finite "
                "pressure");

  scene = BoxedLatticeScene(6, 6);
  LeftWall(scene).drain->conductance_m_per_pa_s = 0.0;
  ExpectRefused(scene,
                "scene.effects[1].walls.walls[1].drain.conductance_m_per_pa_s: must be a finite "
                "number > 0");

  scene = BoxedLatticeScene(6, 6);
  scene.effects = {effects_test::Contacts(), FlowEffectSpec{}};
  ExpectRefused(scene, "scene.boundary.axis: must be set");
  EXPECT_TRUE(ValidateScene(WithOpenEnds(scene)).ok());
}

// A wall contact the detection cannot place is named, with its particle and wall.
TEST(WallsInFluid, AWallContactOfAnUnknownWallIsNamed) {
  const SceneSpec scene = BoxedLatticeScene(6, 6);
  Result<SceneNetwork> built = BuildSceneNetwork(scene);
  ASSERT_TRUE(built.ok()) << built.status().message();
  SceneNetwork net = std::move(*built);
  ASSERT_GT(net.wall_contacts.size(), 0u);
  net.wall_contacts.wall[0] = 9;  // there are four walls
  const Result<SceneNetwork> again = ConnectSceneNetwork(scene, std::move(net));
  ASSERT_FALSE(again.ok());
  EXPECT_EQ(again.status().code(), StatusCode::kInvalidArgument);
  EXPECT_NE(again.status().message().find("scene.effects.walls: domain detection: wall contact 0"),
            std::string::npos)
      << again.status().message();
  EXPECT_NE(again.status().message().find("wall 9"), std::string::npos);
}

// A drained wall is a reservoir at its pressure, joined to every pore it closes by a pipe of the
// scene's conductance per length times the stretch of wall closing that pore.
TEST(WallsInFluid, DrainedPlatensAreReservoirsWithTheScenesConductance) {
  const Result<SceneNetwork> built = BuildSceneNetwork(BoxedLatticeScene(8, 6));
  ASSERT_TRUE(built.ok()) << built.status().message();
  const SceneNetwork& net = *built;
  ASSERT_EQ(net.wall_node.size(), 4u);
  EXPECT_EQ(net.wall_node[0], -1);  // floor: impermeable
  EXPECT_EQ(net.wall_node[3], -1);  // lid
  ASSERT_GE(net.wall_node[1], 0);
  ASSERT_GE(net.wall_node[2], 0);
  const auto left = static_cast<std::size_t>(net.wall_node[1]);
  const auto right = static_cast<std::size_t>(net.wall_node[2]);
  EXPECT_EQ(net.flow.pressure()[left], 2e4);
  EXPECT_EQ(net.flow.pressure()[right], 0.0);
  // Each stretch of a drained wall is one pipe of conductance c x its length.
  double closing_length = 0.0, conductance = 0.0;
  const DomainNetwork& d = net.domains;
  const DomainWalls& walls = d.walls;
  for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
    const std::int32_t c = d.boundary_pipe_contact[k];
    if (!walls.IsWallEdge(c)) continue;
    const std::size_t e = walls.Edge(c);
    if (walls.edge_wall[e] == 1 && walls.edge_particle[e] < 0) closing_length += walls.edge_gap[e];
  }
  for (std::size_t p = 0; p < net.flow.num_pipes(); ++p) {
    if (static_cast<std::size_t>(net.flow.pipe_domain_b()[p]) == left) {
      conductance += net.flow.pipe_conductance()[p];
      EXPECT_EQ(net.pipe_contact[p], -1);
    }
  }
  const double expected = effects_test::kPlatenConductance * closing_length;
  ASSERT_GT(expected, 0.0);
  EXPECT_NEAR(conductance, expected, 1e-12 * expected);
}

}  // namespace
}  // namespace seep::core
