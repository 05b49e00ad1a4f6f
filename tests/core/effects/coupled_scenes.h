// Scenes shared by the coupled-loop tests: small DEM assemblies with pipe flow.
#pragma once

#include <gtest/gtest.h>

#include <functional>
#include <stop_token>
#include <string>
#include <utility>
#include <vector>

#include "seep/core/run/simulation.h"

namespace seep::core::effects_test {

inline constexpr double kRadius = 1e-3;          // m
inline constexpr double kDensity = 2650.0;       // kg/m^3
inline constexpr double kNormalStiffness = 1e7;  // N/m per m

inline Simulation MustCreate(const SceneSpec& scene) {
  Result<Simulation> sim = Simulation::Create(scene);
  EXPECT_TRUE(sim.ok()) << sim.status().message();
  return std::move(*sim);
}

inline void MustRun(Simulation& sim) {
  const Status status = sim.Run({});
  ASSERT_TRUE(status.ok()) << status.message();
}

inline ContactsEffectSpec Contacts() {
  ContactsEffectSpec c;
  c.law.kn = kNormalStiffness;
  c.law.kt = 0.5 * kNormalStiffness;
  c.law.friction = 0.5;
  c.law.damping_mode = NormalDampingMode::kCriticalRatio;
  c.law.damping_ratio = 0.3;
  c.density_kg_m3 = kDensity;
  c.dt_safety = 0.2;
  return c;
}

// A hex lattice in a box of walls (top one servo-loaded), water-like fluid, explicit flow with
// every coupling effect; tests drop or add effects from here. The walls bound the fluid: the side
// walls are porous platens at 20 kPa (left) and 0 (right), each stretch of them about as
// conductive as 25 of the lattice's pipes; floor and lid are impermeable.
inline constexpr double kPlatenConductance = 1e-5;  // m/(Pa s)
inline SceneSpec BoxedLatticeScene(std::uint32_t columns, std::uint32_t rows) {
  SceneSpec s;
  s.name = "boxed lattice";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, columns, rows, kRadius};
  s.packing.contact_gap_m = 1e-6;
  s.fluid.viscosity_pa_s = 1e-3;
  s.fluid.bulk_modulus_pa = 2e8;
  s.aperture.residual_aperture_m = 1e-5;
  s.aperture.reference_force_n = 1e3;
  s.aperture.gap_multiplier = 0.5;
  s.boundary.walls_only = true;
  s.solver.kind = SolverKind::kExplicit;
  s.solver.dt_factor = 0.9;
  s.solver.end_time_s = 2e-3;
  WallsEffectSpec walls;
  walls.walls = {SideWall(WallSide::kBottom),
                 Drained(SideWall(WallSide::kLeft), 2e4, kPlatenConductance),
                 Drained(SideWall(WallSide::kRight), 0.0, kPlatenConductance),
                 SideWall(WallSide::kTop, 2e4, 0.5, 0.05)};
  s.effects = {Contacts(),
               walls,
               LocalDampingEffectSpec{0.3},
               GravityEffectSpec{},
               FlowEffectSpec{},
               FluidForcesEffectSpec{},
               VolumeChangeEffectSpec{},
               ApertureUpdateEffectSpec{}};
  return s;
}

// For a scene whose effects no longer list the walls: the same flow through open ends (a linear
// boundary, 20 kPa at the left end, 0 at the right).
inline SceneSpec WithOpenEnds(SceneSpec s) {
  s.boundary.walls_only = false;
  s.boundary.axis = FlowAxis::kX;
  s.boundary.inlet_pressure_pa = 2e4;
  s.boundary.outlet_pressure_pa = 0.0;
  return s;
}

// Runs `scene` until stop_when holds at a step end, snapshots it (into *mid) and returns a fresh
// simulation restored from that snapshot, not yet run on.
inline Simulation ResumedAt(const SceneSpec& scene,
                            const std::function<bool(const Simulation&)>& stop_when,
                            SimulationSnapshot* mid) {
  Simulation first = MustCreate(scene);
  std::stop_source stop;
  RunControl control;
  control.stop = stop.get_token();
  control.at_step_end = [&](const Simulation& s) {
    if (stop_when(s)) stop.request_stop();
  };
  EXPECT_EQ(first.Run(control).code(), StatusCode::kCancelled);
  *mid = first.TakeSnapshot();
  Simulation resumed = MustCreate(scene);
  const Status restored = resumed.Restore(*mid);
  EXPECT_TRUE(restored.ok()) << restored.message();
  return resumed;
}

// A stage that ends on any of `end` (and fails at max_duration_s, 0 = none).
inline StageSpec Stage(std::string name, std::vector<EndConditionSpec> end,
                       double max_duration_s = 0.0) {
  StageSpec s;
  s.name = std::move(name);
  s.end = std::move(end);
  s.max_duration_s = max_duration_s;
  return s;
}

inline double Metric(const RunReport& report, const std::string& name) {
  for (const auto& [key, value] : report.metrics) {
    if (key == name) return value;
  }
  ADD_FAILURE() << "no metric " << name;
  return 0.0;
}

}  // namespace seep::core::effects_test

namespace seep::core::effects_test {

// Hydraulic fracturing: a bonded hex lattice with a well cut in its centre, confined by four
// servo walls at `confinement_pa`, water injected into the well at a constant rate. The fluid is
// scaled soft (K_f = 1e6 Pa, as PFC users do) so that the DEM step is the contacts'. The walls
// are platens drained at 0 Pa, each stretch about as conductive as two of the sample's pipes.
inline constexpr double kDrainedPlatenConductance = 1e-10;  // m/(Pa s)
inline SceneSpec HydrofracScene(double confinement_pa, double bond_strength_pa) {
  SceneSpec s;
  s.name = "hydraulic fracturing";
  s.packing.source = LatticePackingSpec{LatticeKind::kHex, 24, 28, kRadius};
  s.packing.contact_gap_m = 2e-6;
  s.fluid.viscosity_pa_s = 1e-3;
  s.fluid.bulk_modulus_pa = 1e6;
  s.aperture.residual_aperture_m = 1e-6;
  s.aperture.reference_force_n = 1e2;
  s.aperture.gap_multiplier = 1.0;
  s.aperture.max_aperture_m = 1e-4;
  s.boundary.radial = RadialBoundarySpec{2.5 * kRadius, 1.0, 0.0, 0.0};
  s.solver.kind = SolverKind::kExplicit;
  s.solver.storage = StorageVolume::kPore;
  s.solver.dt_factor = 0.9;
  s.solver.end_time_s = 0.04;
  ContactsEffectSpec contacts = Contacts();
  contacts.law.kn = 1e8;
  contacts.law.kt = 5e7;
  BondsEffectSpec bonds;
  bonds.params = {1e11, 5e10, 1.0, bond_strength_pa, 2.0 * bond_strength_pa};
  bonds.tolerance_m = 1e-6;
  WallsEffectSpec walls;
  for (const WallSide side :
       {WallSide::kLeft, WallSide::kRight, WallSide::kBottom, WallSide::kTop}) {
    walls.walls.push_back(
        Drained(SideWall(side, confinement_pa, 0.5, 0.02), 0.0, kDrainedPlatenConductance));
  }
  s.effects = {contacts,
               bonds,
               walls,
               LocalDampingEffectSpec{0.3},
               FlowEffectSpec{},
               FluidForcesEffectSpec{},
               VolumeChangeEffectSpec{},
               ApertureUpdateEffectSpec{},
               RedetectionEffectSpec{},
               InjectionEffectSpec{2e-4}};
  return s;
}

}  // namespace seep::core::effects_test
