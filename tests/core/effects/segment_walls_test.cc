// Walls anywhere in a scene: a velocity-controlled wall (segment or side) moves exactly v t; a
// grain pile on a tilted segment floor resumes bit-identically (the segment's extent is not in
// the checkpoint: the walls effect gives it again); bad segment walls are named, and a segment
// wall with flow is refused (the fluid's walls are lines).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "coupled_scenes.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {
namespace {

using effects_test::BoxedLatticeScene;
using effects_test::Contacts;
using effects_test::kRadius;
using effects_test::Metric;
using effects_test::MustCreate;
using effects_test::MustRun;
using effects_test::ResumedAt;

struct Box {
  double x_min, y_min, x_max, y_max;
};

Box PackingBox(const SceneSpec& scene) {
  Result<Packing> packing = BuildScenePacking(scene.packing);
  EXPECT_TRUE(packing.ok()) << packing.status().message();
  Box box{std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity(),
          -std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity()};
  for (std::size_t i = 0; i < packing->size(); ++i) {
    box.x_min = std::min(box.x_min, packing->x[i] - packing->radius[i]);
    box.y_min = std::min(box.y_min, packing->y[i] - packing->radius[i]);
    box.x_max = std::max(box.x_max, packing->x[i] + packing->radius[i]);
    box.y_max = std::max(box.y_max, packing->y[i] + packing->radius[i]);
  }
  return box;
}

constexpr double kLidSpeed = 0.05;   // m/s, towards the grains
constexpr double kLeftSpeed = 0.01;  // m/s, inwards

// A hex lattice under gravity, without fluid: a floor segment tilted by 1/20 just below part of
// it, a
// lid segment 0.5 mm above it travelling -x (normal down) at kLidSpeed, and a left side wall
// pushed in at kLeftSpeed.
SceneSpec PileScene() {
  SceneSpec s = BoxedLatticeScene(6, 3);  // its packing, fluid and solver; other effects below
  s.name = "pile on a segment";
  const Box box = PackingBox(s);
  const double x0 = box.x_min - 2.0 * kRadius, x1 = box.x_max + 2.0 * kRadius;
  WallsEffectSpec walls;
  // The floor falls by 1/20 to the right from 1 um under the third disk of the bottom row and
  // starts one radius left of it: the two disks left of that hang beyond its end (as a line it
  // would overlap them by 0.2 mm).
  const double x_third = box.x_min + 5.0 * kRadius;
  const auto floor = [&](double x) { return box.y_min - 1e-6 - 0.05 * (x - x_third); };
  walls.walls = {SegmentWall(x_third - kRadius, floor(x_third - kRadius), x1, floor(x1)),
                 SegmentWall(x1, box.y_max + 5e-4, x0, box.y_max + 5e-4),
                 SideWall(WallSide::kLeft)};
  walls.walls[1].normal_velocity_m_s = kLidSpeed;
  walls.walls[2].normal_velocity_m_s = kLeftSpeed;
  s.effects = {Contacts(), walls, LocalDampingEffectSpec{0.3}, GravityEffectSpec{}};
  return s;
}

TEST(SegmentWalls, VelocityControlledWallsMoveVT) {
  const SceneSpec scene = PileScene();
  const Box box = PackingBox(scene);
  Simulation sim = MustCreate(scene);
  MustRun(sim);
  const double t = sim.time_s();
  ASSERT_GT(t, 0.0);
  const RunReport report = sim.Report();
  // The sum of v dt over the steps: v t to rounding.
  EXPECT_NEAR(Metric(report, "segment1_wall_position_m"), kLidSpeed * t, 1e-12);
  EXPECT_NEAR(Metric(report, "left_wall_position_m"), box.x_min + kLeftSpeed * t, 1e-12);
  // The floor is fixed, and the grains came to rest on it.
  EXPECT_EQ(Metric(report, "segment0_wall_position_m"), 0.0);
  EXPECT_GT(Metric(report, "segment0_wall_stress_pa"), 0.0);
  EXPECT_GT(sim.stepper().state().contacts->wall_loads()[0].contact_count, 0);
}

TEST(SegmentWalls, ResumeOnASegmentFloorIsBitIdentical) {
  const SceneSpec scene = PileScene();
  Simulation reference = MustCreate(scene);
  MustRun(reference);
  const SimulationSnapshot expected = reference.TakeSnapshot();

  const std::uint64_t stop_at = reference.step() / 2;
  SimulationSnapshot mid;
  Simulation resumed = ResumedAt(
      scene, [&](const Simulation& s) { return s.step() == stop_at; }, &mid);
  ASSERT_FALSE(HasFailure());
  MustRun(resumed);
  const SimulationSnapshot got = resumed.TakeSnapshot();
  ASSERT_TRUE(got.mechanics && expected.mechanics);
  EXPECT_EQ(got.step, expected.step);
  // Compared as doubles (no NaN can arise here): the resumed run matches the uninterrupted one.
  EXPECT_EQ(got.mechanics->x, expected.mechanics->x);
  EXPECT_EQ(got.mechanics->y, expected.mechanics->y);
  EXPECT_EQ(got.mechanics->walls, expected.mechanics->walls);
  EXPECT_EQ(got.mechanics->contacts.wall_contact_shear,
            expected.mechanics->contacts.wall_contact_shear);
  EXPECT_EQ(got.series.values, expected.series.values);
  // The run after the resume touched the segment floor (its extent came back with the walls).
  EXPECT_GT(resumed.stepper().state().contacts->wall_loads()[0].contact_count, 0);
}

std::string Refusal(const SceneSpec& scene) {
  Result<Simulation> sim = Simulation::Create(scene);
  EXPECT_FALSE(sim.ok());
  if (sim.ok()) return "";
  EXPECT_EQ(sim.status().code(), StatusCode::kInvalidArgument);
  return sim.status().message();
}

WallSpec& Wall(SceneSpec& scene, std::size_t k) {
  return std::get<WallsEffectSpec>(scene.effects[1]).walls[k];
}

TEST(SegmentWalls, BadSegmentWallsAreNamed) {
  {
    SceneSpec s = PileScene();
    Wall(s, 0).segment->x1_m = Wall(s, 0).segment->x0_m;
    Wall(s, 0).segment->y1_m = Wall(s, 0).segment->y0_m;
    EXPECT_NE(Refusal(s).find("scene.effects[1].walls.walls[0].x1_m: the segment has zero length"),
              std::string::npos);
  }
  {
    SceneSpec s = PileScene();
    Wall(s, 1).segment->y0_m = std::numeric_limits<double>::quiet_NaN();
    EXPECT_NE(Refusal(s).find("scene.effects[1].walls.walls[1].y0_m: must be finite"),
              std::string::npos);
  }
  {
    SceneSpec s = PileScene();
    Wall(s, 1).servo_stress_pa = 1e4;
    Wall(s, 1).servo_max_speed_m_s = 0.1;
    EXPECT_NE(Refusal(s).find("scene.effects[1].walls.walls[1].normal_velocity_m_s: a wall is "
                              "servo-controlled"),
              std::string::npos);
  }
  {
    SceneSpec s = PileScene();
    Wall(s, 2).normal_velocity_m_s = std::numeric_limits<double>::infinity();
    EXPECT_NE(Refusal(s).find("scene.effects[1].walls.walls[2].normal_velocity_m_s: must be "
                              "finite"),
              std::string::npos);
  }
  {
    // Two segment walls need no distinct sides (the side check is the side walls').
    SceneSpec s = PileScene();
    Wall(s, 1).side = Wall(s, 0).side;
    EXPECT_TRUE(ValidateScene(s).ok());
  }
}

TEST(SegmentWalls, ASegmentWallWithFlowIsRefused) {
  SceneSpec s = BoxedLatticeScene(4, 4);
  const Box box = PackingBox(s);
  std::get<WallsEffectSpec>(s.effects[1]).walls[0] =
      SegmentWall(box.x_min, box.y_min, box.x_max, box.y_min);
  EXPECT_NE(Refusal(s).find("scene.effects[1].walls.walls[0].x0_m: a wall given by its end "
                            "points cannot bound the fluid"),
            std::string::npos);
}

}  // namespace
}  // namespace seep::core
