#include "bad_scenes.h"

#include <limits>

namespace seep::testing {
namespace {
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// A valid random packing spec without a target: the cases below break one field of it.
v1::RandomPacking* RandomBox(v1::Scene& scene) {
  auto* r = scene.mutable_packing()->mutable_random();
  r->set_width_m(1);
  r->set_height_m(1);
  r->set_min_radius_m(0.01);
  r->set_max_radius_m(0.02);
  r->set_particle_count(100);
  return r;
}

// Adds a valid contacts effect (effects[0]) and a walls effect (effects[1]) with one wall, the
// segment (0, 0) -> (1, 0), which the cases below break.
v1::Wall* SegmentWall(v1::Scene& scene) {
  auto* contacts = scene.add_effects()->mutable_contacts();
  contacts->mutable_law()->set_kn_n_per_m(1e7);
  contacts->mutable_law()->set_damping(v1::NORMAL_DAMPING_CRITICAL_RATIO);
  contacts->set_density_kg_m3(2650);
  v1::Wall* wall = scene.add_effects()->mutable_walls()->add_walls();
  wall->set_x0_m(0);
  wall->set_y0_m(0);
  wall->set_x1_m(1);
  wall->set_y1_m(0);
  return wall;
}

// Adds a valid boundary region (a circle at 1e5 Pa) for the cases below to break.
v1::BoundaryRegion* CircleRegion(v1::Scene& scene, const char* name) {
  v1::BoundaryRegion* region = scene.mutable_boundary()->add_regions();
  region->set_name(name);
  region->mutable_circle()->set_cx_m(0.002);
  region->mutable_circle()->set_cy_m(0.002);
  region->mutable_circle()->set_r_m(0.001);
  region->set_pressure_pa(1e5);
  return region;
}

}  // namespace

const std::vector<BadScene>& CommonBadScenes() {
  static const std::vector<BadScene> scenes = {
      {"NoPacking", [](v1::Scene& s) { s.clear_packing(); }, "scene.packing:"},
      {"LatticeKindUnset",
       [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->clear_kind(); },
       "scene.packing.lattice.kind:"},
      {"OneColumn", [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_columns(1); },
       "scene.packing.lattice.columns:"},
      {"NoRows", [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_rows(0); },
       "scene.packing.lattice.rows:"},
      {"NegativeRadius",
       [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_radius_m(-1); },
       "scene.packing.lattice.radius_m:"},
      {"NaNRadius",
       [](v1::Scene& s) { s.mutable_packing()->mutable_lattice()->set_radius_m(kNaN); },
       "scene.packing.lattice.radius_m:"},
      {"HugeLattice",
       [](v1::Scene& s) {
         s.mutable_packing()->mutable_lattice()->set_columns(100000);
         s.mutable_packing()->mutable_lattice()->set_rows(100000);
       },
       "scene.packing.lattice:"},
      {"ParticleArraysOfUnequalLength",
       [](v1::Scene& s) {
         auto* p = s.mutable_packing()->mutable_particles();
         for (int i = 0; i < 3; ++i) {
           p->add_x_m(i);
           p->add_y_m(0);
           p->add_radius_m(0.5);
         }
         p->add_x_m(4);
       },
       "scene.packing.particles:"},
      {"ParticleWithZeroRadius",
       [](v1::Scene& s) {
         auto* p = s.mutable_packing()->mutable_particles();
         for (int i = 0; i < 3; ++i) {
           p->add_x_m(i);
           p->add_y_m(0);
           p->add_radius_m(i == 2 ? 0.0 : 0.5);
         }
       },
       "scene.packing.particles[2].radius_m:"},
      {"RandomPorosityAboveOne",
       [](v1::Scene& s) {
         auto* r = RandomBox(s);
         r->set_target_porosity(1.5);
       },
       "scene.packing.random.target_porosity:"},
      {"RandomRadiiSwapped",
       [](v1::Scene& s) {
         auto* r = RandomBox(s);
         r->set_min_radius_m(0.02);
         r->set_max_radius_m(0.01);
         r->set_target_porosity(0.2);
       },
       "scene.packing.random.max_radius_m:"},
      {"RandomWithoutTarget", [](v1::Scene& s) { RandomBox(s); }, "scene.packing.random.target:"},
      {"NegativeContactGap", [](v1::Scene& s) { s.mutable_packing()->set_contact_gap_m(-1); },
       "scene.packing.contact_gap_m:"},
      {"ZeroViscosity", [](v1::Scene& s) { s.mutable_fluid()->set_viscosity_pa_s(0); },
       "scene.fluid.viscosity_pa_s:"},
      {"NegativeViscosity", [](v1::Scene& s) { s.mutable_fluid()->set_viscosity_pa_s(-1); },
       "scene.fluid.viscosity_pa_s:"},
      {"InfiniteBulkModulus", [](v1::Scene& s) { s.mutable_fluid()->set_bulk_modulus_pa(kInf); },
       "scene.fluid.bulk_modulus_pa:"},
      {"NegativeFluidDensity", [](v1::Scene& s) { s.mutable_fluid()->set_density_kg_m3(-1000); },
       "scene.fluid.density_kg_m3: must be a finite number >= 0"},
      {"NaNFluidDensity", [](v1::Scene& s) { s.mutable_fluid()->set_density_kg_m3(kNaN); },
       "scene.fluid.density_kg_m3: must be a finite number >= 0"},
      {"InfiniteFluidDensity", [](v1::Scene& s) { s.mutable_fluid()->set_density_kg_m3(kInf); },
       "scene.fluid.density_kg_m3: must be a finite number >= 0"},
      {"HydrostaticStartWithoutWeight",
       [](v1::Scene& s) { s.mutable_boundary()->set_initial_pressure_hydrostatic(true); },
       "scene.boundary.initial_pressure_hydrostatic: needs a fluid with weight"},
      {"HydrostaticReferenceNotFinite",
       [](v1::Scene& s) { s.mutable_boundary()->set_initial_pressure_y_m(kInf); },
       "scene.boundary.initial_pressure_y_m: must be finite"},
      {"NoResidualAperture", [](v1::Scene& s) { s.mutable_aperture()->set_residual_aperture_m(0); },
       "scene.aperture.residual_aperture_m:"},
      {"NegativeGapMultiplier",
       [](v1::Scene& s) { s.mutable_aperture()->set_gap_multiplier(-0.1); },
       "scene.aperture.gap_multiplier:"},
      {"CapBelowA0", [](v1::Scene& s) { s.mutable_aperture()->set_max_aperture_m(1e-6); },
       "scene.aperture.max_aperture_m:"},
      {"AxisUnset", [](v1::Scene& s) { s.mutable_boundary()->clear_axis(); },
       "scene.boundary.axis:"},
      {"NaNInletPressure", [](v1::Scene& s) { s.mutable_boundary()->set_inlet_pressure_pa(kNaN); },
       "scene.boundary.inlet_pressure_pa:"},
      {"SolverKindUnset", [](v1::Scene& s) { s.mutable_solver()->clear_kind(); },
       "scene.solver.kind:"},
      {"TransientWithoutStorage",
       [](v1::Scene& s) {
         s.mutable_solver()->set_kind(v1::SOLVER_KIND_IMPLICIT);
         s.mutable_solver()->set_dt_factor(10);
         s.mutable_solver()->set_end_time_s(1);
         s.mutable_solver()->clear_storage();
       },
       "scene.solver.storage:"},
      {"NoEndTime",
       [](v1::Scene& s) {
         s.mutable_solver()->set_kind(v1::SOLVER_KIND_IMPLICIT);
         s.mutable_solver()->set_storage(v1::STORAGE_VOLUME_PORE);
         s.mutable_solver()->set_dt_factor(10);
         s.mutable_solver()->clear_end_time_s();
       },
       "scene.solver.end_time_s:"},
      {"ExplicitAboveTheCriticalStep",
       [](v1::Scene& s) {
         s.mutable_solver()->set_kind(v1::SOLVER_KIND_EXPLICIT);
         s.mutable_solver()->set_storage(v1::STORAGE_VOLUME_PORE);
         s.mutable_solver()->set_dt_factor(1.5);
         s.mutable_solver()->set_end_time_s(1);
       },
       "scene.solver.dt_factor:"},
      {"StorageFactorAboveOne", [](v1::Scene& s) { s.mutable_solver()->set_storage_factor(1.5); },
       "scene.solver.storage_factor: must lie in (0, 1]"},
      {"StorageFactorZero", [](v1::Scene& s) { s.mutable_solver()->set_storage_factor(0.0); },
       "scene.solver.storage_factor: must lie in (0, 1]"},
      {"StorageFloorOfOne",
       [](v1::Scene& s) { s.mutable_solver()->set_storage_floor_fraction(1.0); },
       "scene.solver.storage_floor_fraction: must lie in [0, 1)"},
      {"LinearSolverUnknown",
       [](v1::Scene& s) {
         s.mutable_solver()->set_linear_solver(static_cast<v1::LinearSolver>(9));
       },
       "scene.solver.linear_solver: must be LINEAR_SOLVER_CHOLMOD_SUPERNODAL"},
      {"EffectNamesNothing", [](v1::Scene& s) { s.add_effects(); }, "scene.effects[0]:"},
      {"GravityWithoutContacts",
       [](v1::Scene& s) { s.add_effects()->mutable_gravity()->set_gy_m_s2(-9.81); },
       "scene.effects[0].gravity: requires the contacts effect"},
      {"ContactDampingUnset",
       [](v1::Scene& s) {
         auto* contacts = s.add_effects()->mutable_contacts();
         contacts->mutable_law()->set_kn_n_per_m(1e7);
         contacts->set_density_kg_m3(2650);
       },
       "scene.effects[0].contacts.law.damping:"},
      {"WallSideUnset",
       [](v1::Scene& s) {
         auto* contacts = s.add_effects()->mutable_contacts();
         contacts->mutable_law()->set_kn_n_per_m(1e7);
         contacts->mutable_law()->set_damping(v1::NORMAL_DAMPING_CRITICAL_RATIO);
         contacts->set_density_kg_m3(2650);
         s.add_effects()->mutable_walls()->add_walls();
       },
       "scene.effects[1].walls.walls[0].side:"},
      {"WallEndPointMissing", [](v1::Scene& s) { SegmentWall(s)->clear_y1_m(); },
       "scene.effects[1].walls.walls[0].y1_m: a wall given by its end points needs all four"},
      {"WallSideAndEndPoints", [](v1::Scene& s) { SegmentWall(s)->set_side(v1::WALL_SIDE_LEFT); },
       "scene.effects[1].walls.walls[0].side: a wall is given by its side or by its end points"},
      {"WallZeroLength", [](v1::Scene& s) { SegmentWall(s)->set_x1_m(0); },
       "scene.effects[1].walls.walls[0].x1_m: the segment has zero length"},
      {"WallEndPointNaN", [](v1::Scene& s) { SegmentWall(s)->set_x0_m(kNaN); },
       "scene.effects[1].walls.walls[0].x0_m: must be finite"},
      {"WallServoAndVelocity",
       [](v1::Scene& s) {
         v1::Wall* wall = SegmentWall(s);
         wall->set_servo_stress_pa(1e5);
         wall->set_servo_max_speed_m_s(0.1);
         wall->set_normal_velocity_m_s(0.01);
       },
       "scene.effects[1].walls.walls[0].normal_velocity_m_s: a wall is servo-controlled"},
      {"WallVelocityInfinite", [](v1::Scene& s) { SegmentWall(s)->set_normal_velocity_m_s(kInf); },
       "scene.effects[1].walls.walls[0].normal_velocity_m_s: must be finite"},
      {"SegmentWallWithFlow",
       [](v1::Scene& s) {
         SegmentWall(s);
         s.add_effects()->mutable_flow();
       },
       "scene.effects[1].walls.walls[0].x0_m: a wall given by its end points cannot bound the "
       "fluid"},
      {"RegionWithoutShape", [](v1::Scene& s) { CircleRegion(s, "a")->clear_circle(); },
       "scene.boundary.regions[0]: set one shape (box, circle, half_plane, polygon)"},
      {"RegionWithoutCondition", [](v1::Scene& s) { CircleRegion(s, "a")->clear_pressure_pa(); },
       "scene.boundary.regions[0]: set one condition (pressure_pa, flux_m2_s)"},
      {"RegionNameWithCapitals", [](v1::Scene& s) { CircleRegion(s, "Outlet"); },
       "scene.boundary.regions[0].name: only a-z, 0-9 and _"},
      {"RegionCircleWithoutRadius",
       [](v1::Scene& s) { CircleRegion(s, "a")->mutable_circle()->set_r_m(0); },
       "scene.boundary.regions[0].circle.r_m: must be a finite number > 0"},
      {"RegionsOverlapWithDifferentConditions",
       [](v1::Scene& s) {
         CircleRegion(s, "a");
         CircleRegion(s, "b")->set_flux_m2_s(1e-7);
       },
       "scene.boundary.regions[1] ('b'): overlaps regions[0] ('a') with a different condition; "
       "a domain in both would have two"},
  };
  return scenes;
}

}  // namespace seep::testing
