// Fluid weight on walls (issue 49): the push of the fluid on a wall is the integral of the
// pressure along the stretches of it the pores wet, and does not depend on where the origin is.
//
// A sealed box of a hex lattice, the fluid at rest under gravity (the hydrostatic start): each
// pore's pressure is p(x) = Phi + w.x along its face, so the base feels exactly the hydrostatic
// pressure at its height times the length of base the pores wet, and the same box moved up by a
// metre feels the same push. The chord rule on the heads Phi alone (which the particles' forces
// use, with Archimedes for the rest) missed w.x along the walls: the push then moved by rho_f g x
// y_wall per metre of wall with the origin.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "scene_maps.h"
#include "seep/core/network/fluid_weight.h"
#include "seep/core/run/simulation.h"

namespace seep::core::metamorphic {
namespace {

constexpr double kRadius = 1e-3;
constexpr double kFluidDensity = 1000.0;
constexpr double kGravity = 9.81;
constexpr double kReferencePressure = 5e3;  // Pa at the reference point

SceneSpec SealedBoxAtRest() {
  SceneSpec s;
  s.name = "sealed box at rest";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, 8, 10, kRadius};
  s.packing.contact_gap_m = 1e-6;
  s.fluid.viscosity_pa_s = 1e-3;
  s.fluid.bulk_modulus_pa = 2e8;
  s.fluid.density_kg_m3 = kFluidDensity;
  s.aperture.residual_aperture_m = 1e-5;
  s.aperture.reference_force_n = 1e3;
  s.boundary.walls_only = true;
  s.boundary.initial_pressure_pa = kReferencePressure;
  s.boundary.initial_pressure_hydrostatic = true;
  s.boundary.initial_pressure_x_m = 0.0;
  s.boundary.initial_pressure_y_m = 0.02;
  s.solver.kind = SolverKind::kImplicit;
  s.solver.dt_factor = 10.0;
  s.solver.end_time_s = 1e-4;
  ContactsEffectSpec contacts;
  contacts.law.kn = 1e7;
  contacts.law.kt = 5e6;
  contacts.law.friction = 0.5;
  contacts.density_kg_m3 = 2650.0;
  WallsEffectSpec walls;
  walls.walls = {SideWall(WallSide::kBottom), SideWall(WallSide::kLeft), SideWall(WallSide::kRight),
                 SideWall(WallSide::kTop)};
  s.effects = {contacts,
               walls,
               GravityEffectSpec{0.0, -kGravity},
               FlowEffectSpec{},
               FluidForcesEffectSpec{},
               VolumeChangeEffectSpec{}};
  return s;
}

struct BasePush {
  double force = 0.0;          // N per m, the fluid's push on the base (wall 0)
  double wetted_length = 0.0;  // m, the stretches of the base that close a pore
  double height = 0.0;         // m, the base's y
};

BasePush PushOnTheBase(const SceneSpec& scene) {
  Result<Simulation> created = Simulation::Create(scene);
  EXPECT_TRUE(created.ok()) << created.status().message();
  if (!created.ok()) return {};
  const Simulation& sim = *created;
  const LiveState& s = sim.stepper().state();
  BasePush out;
  out.force = s.wall_pore_force[0];
  out.height = s.walls[0].py;
  // The stretches along wall 0 of every pore's loop, at the detection (nothing has moved yet).
  const DomainWalls& walls = s.net.domains.walls;
  for (const WallStretch& stretch : WettedWallStretches(s.net.domains)) {
    if (stretch.wall != 0) continue;
    const auto u = static_cast<std::size_t>(stretch.from - walls.num_particles);
    const auto v = static_cast<std::size_t>(stretch.to - walls.num_particles);
    out.wetted_length +=
        std::hypot(walls.vertex_x[v] - walls.vertex_x[u], walls.vertex_y[v] - walls.vertex_y[u]);
  }
  return out;
}

TEST(FluidWeightOnWalls, TheBaseFeelsTheHydrostaticPressureTimesItsWettedLength) {
  const SceneSpec scene = SealedBoxAtRest();
  const BasePush base = PushOnTheBase(scene);
  const double pressure =
      kReferencePressure +
      kFluidDensity * kGravity * (scene.boundary.initial_pressure_y_m - base.height);
  std::printf(
      "base at y = %.6g m: push %.9g N/m over %.6g m wetted, %.9g Pa; hydrostatic %.9g Pa\n",
      base.height, base.force, base.wetted_length, base.force / base.wetted_length, pressure);
  ASSERT_GT(base.wetted_length, 0.0);
  // Exact in the model (the field is linear along each stretch; the heads are one value at
  // rest): round-off of sums of about ten terms.
  EXPECT_NEAR(base.force / base.wetted_length, pressure, 1e-12 * pressure);
}

TEST(FluidWeightOnWalls, ThePushDoesNotDependOnTheOrigin) {
  const SceneSpec scene = SealedBoxAtRest();
  const BasePush here = PushOnTheBase(MaterialisedScene(scene));
  for (const SceneMap& map : {SceneMap{Turn::kNone, 0.0, 1.0}, SceneMap{Turn::kNone, -3.5, 0.0},
                              SceneMap{Turn::kNone, 12.25, -7.75}}) {
    const BasePush there = PushOnTheBase(*MapScene(scene, map).scene);
    SCOPED_TRACE(map.Name());
    // The translated box is exactly the image (scene_maps.h); what differs is round-off in
    // w.x at the larger coordinates: 1e-9 of the push leaves six orders above it and fails the
    // missing term (rho_f g x 1 m over 1.6 cm of base is 25 % of the push).
    EXPECT_NEAR(there.force, here.force, 1e-9 * std::abs(here.force));
    // The wall vertices are projections and corners computed at other coordinates: round-off.
    EXPECT_NEAR(there.wetted_length, here.wetted_length, 1e-12 * here.wetted_length);
  }
}

}  // namespace
}  // namespace seep::core::metamorphic
