#include "scene_generator.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <random>
#include <stdexcept>
#include <utility>

#include "seep/core/network/scene_network.h"
#include "seep/core/run/simulation.h"

namespace seep::core::metamorphic {
namespace {

// Draws by hand from std::mt19937_64, whose sequence the standard fixes.
class Draw {
 public:
  explicit Draw(std::uint64_t seed) : engine_(seed) {}
  double Uniform(double lo, double hi) {
    return lo + (hi - lo) * static_cast<double>(engine_() >> 11) * 0x1.0p-53;
  }
  double LogUniform(double lo, double hi) { return std::exp(Uniform(std::log(lo), std::log(hi))); }
  // An integer in [lo, hi].
  int Int(int lo, int hi) {
    return lo + static_cast<int>(engine_() % static_cast<std::uint64_t>(hi - lo + 1));
  }
  bool Chance(double p) { return Uniform(0.0, 1.0) < p; }

 private:
  std::mt19937_64 engine_;
};

struct Box {
  double x0, y0, x1, y1;
  double cx() const { return 0.5 * (x0 + x1); }
  double cy() const { return 0.5 * (y0 + y1); }
};

Box BoundingBox(const PackingSpec& spec) {
  const Result<Packing> p = BuildScenePacking(spec);
  Box b{1e300, 1e300, -1e300, -1e300};
  if (!p.ok()) return b;
  for (std::size_t i = 0; i < p->size(); ++i) {
    b.x0 = std::min(b.x0, p->x[i] - p->radius[i]);
    b.y0 = std::min(b.y0, p->y[i] - p->radius[i]);
    b.x1 = std::max(b.x1, p->x[i] + p->radius[i]);
    b.y1 = std::max(b.y1, p->y[i] + p->radius[i]);
  }
  return b;
}

// A packing of about `count` disks of radius about `radius`: a lattice, a random packing or a
// listed one (a hex lattice whose radii shrink by up to 0.2 %, so its contacts have gaps within
// the contact gap), with the contact gap that suits it.
void DrawPacking(Draw& d, int min_side, int max_side, double radius, bool allow_square,
                 PackingSpec* out) {
  const int kind = d.Int(0, allow_square ? 3 : 2);
  const auto columns = static_cast<std::uint32_t>(d.Int(min_side, max_side));
  const auto rows = static_cast<std::uint32_t>(d.Int(min_side, max_side));
  out->contact_gap_m = 1e-3 * radius;
  if (kind == 0 || kind == 3) {
    out->source = LatticePackingSpec{kind == 0 ? LatticeKind::kHex : LatticeKind::kSquare, columns,
                                     rows, radius};
    return;
  }
  if (kind == 1) {
    RandomPackingSpec r;
    r.seed = static_cast<std::uint64_t>(d.Int(1, 1 << 30));
    r.particle_count = columns * rows;
    r.max_radius_m = radius;
    r.min_radius_m = radius / d.Uniform(1.0, 1.66);
    const double mean = 0.5 * (r.min_radius_m + r.max_radius_m);
    // A square of about the disks' area at porosity 0.3.
    const double side =
        std::sqrt(static_cast<double>(r.particle_count) * std::numbers::pi * mean * mean / 0.7);
    r.width_m = side;
    r.height_m = side;
    r.target_porosity = d.Uniform(0.2, 0.26);
    out->source = r;
    out->contact_gap_m = 0.04 * mean;
    return;
  }
  const Result<Packing> lattice =
      HexLattice(static_cast<int>(columns), static_cast<int>(rows), radius);
  ParticleListSpec list;
  list.x_m = lattice->x;
  list.y_m = lattice->y;
  for (const double r : lattice->radius) list.radius_m.push_back(r * (1.0 - d.Uniform(0, 2e-3)));
  out->source = std::move(list);
  out->contact_gap_m = 1e-2 * radius;
}

// Scaled soft fluids, as coupled DEM studies use them, and real water (K_f = 2.2e9 Pa) one time
// in five where `real_water` allows it (both are drawn either way: the same stream of draws).
void DrawFluid(Draw& d, bool real_water, SceneSpec* s) {
  s->fluid.viscosity_pa_s = d.LogUniform(1e-4, 1e-2);
  const bool water = d.Chance(0.2);
  const double scaled = d.LogUniform(1e6, 2e8);
  s->fluid.bulk_modulus_pa = water && real_water ? 2.2e9 : scaled;
}

void DrawFluidWeight(Draw& d, const Box& box, bool any_direction, SceneSpec* s,
                     GravityEffectSpec* gravity) {
  const double angle = any_direction ? d.Uniform(-std::numbers::pi, std::numbers::pi) : 0.0;
  gravity->gx_m_s2 = 9.81 * std::sin(angle);
  gravity->gy_m_s2 = -9.81 * std::cos(angle);
  s->fluid.density_kg_m3 = d.Uniform(900.0, 1300.0);
  if (d.Chance(0.5)) {
    s->boundary.initial_pressure_hydrostatic = true;
    s->boundary.initial_pressure_x_m = box.cx();
    s->boundary.initial_pressure_y_m = box.y1;
  }
}

SceneSpec Frozen(Draw& d) {
  SceneSpec s;
  const double radius = d.LogUniform(2e-4, 2e-3);
  DrawPacking(d, 6, 14, radius, true, &s.packing);
  DrawFluid(d, true, &s);
  s.aperture.residual_aperture_m = d.LogUniform(5e-3, 2e-2) * radius;
  s.aperture.gap_multiplier = d.Uniform(0.0, 0.5);
  const Box box = BoundingBox(s.packing);
  const double pressure = d.LogUniform(1e3, 1e6);
  const int boundary = d.Int(0, 3);
  if (boundary == 0) {
    const double well = d.Uniform(1.5, 3.0) * radius;
    s.boundary.radial = RadialBoundarySpec{well, 1.0, pressure, d.Uniform(0.0, 0.3) * pressure};
  } else {
    s.boundary.axis = d.Chance(0.5) ? FlowAxis::kX : FlowAxis::kY;
    s.boundary.inlet_pressure_pa = pressure;
    s.boundary.outlet_pressure_pa = d.Uniform(0.0, 0.5) * pressure;
    s.boundary.closed_inlet = d.Chance(0.15);
  }
  s.boundary.initial_pressure_pa = d.Uniform(0.0, 0.5) * pressure;
  const int solver = d.Int(0, 3);
  s.solver.kind = solver == 0   ? SolverKind::kSteady
                  : solver == 1 ? SolverKind::kExplicit
                  : solver == 2 ? SolverKind::kImplicit
                                : SolverKind::kCrankNicolson;
  s.solver.dt_factor = solver == 1   ? d.Uniform(0.3, 0.95)
                       : solver == 2 ? d.LogUniform(1.0, 50.0)
                                     : d.Uniform(0.5, 5.0);
  s.solver.storage = d.Chance(0.7) ? StorageVolume::kPore : StorageVolume::kApparent;
  s.solver.storage_floor_fraction = d.Chance(0.5) ? d.Uniform(0.02, 0.1) : 0.0;
  s.solver.end_time_s = 1.0;  // replaced by the step count (GenerateScene)
  s.effects = {FlowEffectSpec{}};
  if (d.Chance(0.3)) {
    GravityEffectSpec gravity;
    DrawFluidWeight(d, box, true, &s, &gravity);
    s.effects.push_back(gravity);
  }
  if (d.Chance(0.3)) {
    BoundaryRegionSpec region;
    region.name = "middle";
    region.shape = d.Chance(0.5)
                       ? RegionShape{CircleShape{box.cx(), box.cy(), 3.0 * radius}}
                       : RegionShape{BoxShape{box.cx() - 2.5 * radius, box.cy() - 2.5 * radius,
                                              box.cx() + 2.5 * radius, box.cy() + 2.5 * radius}};
    if (d.Chance(0.5)) {
      region.condition = FixedPressure{d.Uniform(0.0, 1.0) * pressure};
    } else {
      region.condition = FixedFlux{d.LogUniform(1e-12, 1e-9)};
    }
    s.boundary.regions.push_back(std::move(region));
  }
  return s;
}

ContactsEffectSpec DrawContacts(Draw& d) {
  ContactsEffectSpec c;
  c.law.kn = d.LogUniform(1e6, 1e8);
  c.law.kt = d.Uniform(0.3, 0.7) * c.law.kn;
  c.law.friction = d.Uniform(0.2, 0.6);
  c.law.damping_mode = NormalDampingMode::kCriticalRatio;
  c.law.damping_ratio = d.Chance(0.8) ? d.Uniform(0.05, 0.4) : 0.0;
  c.density_kg_m3 = 2650.0;
  c.dt_safety = d.Uniform(0.1, 0.3);
  return c;
}

BondsEffectSpec DrawBonds(Draw& d, const ContactsEffectSpec& contacts, double radius,
                          double min_strength, double max_strength) {
  BondsEffectSpec b;
  b.params.normal_stiffness = contacts.law.kn * d.Uniform(0.5, 3.0) / (2.0 * radius);
  b.params.shear_stiffness = 0.5 * b.params.normal_stiffness;
  b.params.radius_multiplier = 1.0;
  b.params.tensile_strength = d.LogUniform(min_strength, max_strength);
  b.params.shear_strength = 2.0 * b.params.tensile_strength;
  b.tolerance_m = 2e-3 * radius;
  return b;
}

void DrawCoupledFlow(Draw& d, double radius, double kn, bool real_water, SceneSpec* s) {
  DrawFluid(d, real_water, s);
  s->aperture.residual_aperture_m = d.LogUniform(1e-3, 1e-2) * radius;
  s->aperture.reference_force_n = kn * radius * d.LogUniform(1e-3, 1e-1);
  s->aperture.gap_multiplier = d.Uniform(0.2, 1.0);
  s->aperture.max_aperture_m = d.Chance(0.5) ? 0.1 * radius : 0.0;
  const bool implicit = d.Chance(0.5);
  s->solver.kind = implicit ? SolverKind::kImplicit : SolverKind::kExplicit;
  s->solver.dt_factor = implicit ? d.LogUniform(1.0, 1e3) : d.Uniform(0.3, 0.9);
  s->solver.storage = StorageVolume::kPore;
  s->solver.storage_floor_fraction = 0.05;
  s->solver.end_time_s = 1.0;  // replaced by the step count (GenerateScene)
}

SceneSpec SampleInBox(Draw& d, bool real_water) {
  SceneSpec s;
  const double radius = d.LogUniform(5e-4, 2e-3);
  DrawPacking(d, 7, 13, radius, false, &s.packing);
  const ContactsEffectSpec contacts = DrawContacts(d);
  DrawCoupledFlow(d, radius, contacts.law.kn, real_water, &s);
  const Box box = BoundingBox(s.packing);
  s.boundary.walls_only = true;
  s.boundary.initial_pressure_pa = d.Uniform(0.0, 1e4);
  WallsEffectSpec walls;
  walls.walls.push_back(SideWall(WallSide::kBottom));
  for (const WallSide side : {WallSide::kLeft, WallSide::kRight}) {
    WallSpec wall = SideWall(side);
    if (d.Chance(0.5)) wall = Drained(wall, d.Uniform(0.0, 1e4), d.LogUniform(1e-7, 1e-4));
    walls.walls.push_back(wall);
  }
  WallSpec lid = SideWall(WallSide::kTop);
  if (d.Chance(0.7)) {
    lid = SideWall(WallSide::kTop, d.LogUniform(1e3, 5e4), 0.5, 0.02);
    lid.servo_effective_stress = d.Chance(0.2);
  }
  walls.walls.push_back(lid);
  s.effects = {contacts, walls, FlowEffectSpec{}, FluidForcesEffectSpec{},
               VolumeChangeEffectSpec{}};
  if (d.Chance(0.4)) s.effects.push_back(DrawBonds(d, contacts, radius, 1e5, 1e7));
  if (d.Chance(0.7)) s.effects.push_back(LocalDampingEffectSpec{d.Uniform(0.1, 0.7)});
  if (d.Chance(0.6)) s.effects.push_back(ApertureUpdateEffectSpec{});
  if (d.Chance(0.6)) s.effects.push_back(RedetectionEffectSpec{});
  if (d.Chance(0.7)) {
    GravityEffectSpec gravity;
    if (d.Chance(0.5)) {
      DrawFluidWeight(d, box, false, &s, &gravity);
    }
    s.effects.push_back(gravity);
  }
  return s;
}

SceneSpec DiscAroundAWell(Draw& d, bool real_water) {
  SceneSpec s;
  const double radius = d.LogUniform(5e-4, 2e-3);
  DrawPacking(d, 10, 16, radius, false, &s.packing);
  ContactsEffectSpec contacts = DrawContacts(d);
  DrawCoupledFlow(d, radius, contacts.law.kn, real_water, &s);
  const double well_pressure = d.LogUniform(1e4, 1e6);
  s.boundary.radial = RadialBoundarySpec{2.5 * radius, 1.0, well_pressure, 0.0};
  s.effects = {contacts,
               DrawBonds(d, contacts, radius, 3e5, 3e7),
               FlowEffectSpec{},
               FluidForcesEffectSpec{},
               VolumeChangeEffectSpec{},
               ApertureUpdateEffectSpec{},
               RedetectionEffectSpec{},
               LocalDampingEffectSpec{d.Uniform(0.1, 0.7)}};
  if (d.Chance(0.6)) s.effects.push_back(InjectionEffectSpec{d.LogUniform(1e-6, 1e-4)});
  if (d.Chance(0.5)) {
    WallsEffectSpec walls;
    const double confinement = d.LogUniform(1e4, 1e6);
    for (const WallSide side :
         {WallSide::kLeft, WallSide::kRight, WallSide::kBottom, WallSide::kTop}) {
      walls.walls.push_back(Drained(SideWall(side, confinement, 0.5, 0.02), 0.0, 1e-10));
    }
    s.effects.push_back(walls);
  }
  return s;
}

}  // namespace

const char* FamilyName(Family family) {
  switch (family) {
    case Family::kFrozen:
      return "frozen";
    case Family::kBox:
      return "box";
    case Family::kDisc:
      return "disc";
  }
  return "unknown";
}

constexpr std::uint64_t kMaxAttempts = 100;

GeneratedScene GenerateScene(std::uint64_t seed, const GeneratorOptions& options) {
  // A draw the product refuses (a random packing too dense to place, a sample one particle
  // long) is drawn again from the next sub-seed: the scenes are the valid ones.
  for (std::uint64_t attempt = 0; attempt < kMaxAttempts; ++attempt) {
    Draw d(seed * 1'000'003 + attempt);
    GeneratedScene g;
    const int family = d.Int(0, 9);
    g.family = family < 4 ? Family::kFrozen : family < 8 ? Family::kBox : Family::kDisc;
    g.scene = g.family == Family::kFrozen ? Frozen(d)
              : g.family == Family::kBox  ? SampleInBox(d, options.coupled_real_water)
                                          : DiscAroundAWell(d, options.coupled_real_water);
    g.scene.name = fmt::format("generated {} {}", FamilyName(g.family), seed);
    g.steps = static_cast<std::uint64_t>(d.Int(40, 150));
    if (!ValidateScene(g.scene).ok()) continue;
    Result<Simulation> sim = Simulation::Create(g.scene);
    if (!sim.ok()) continue;
    // The run ends half a step past the laws' last step: every map of it takes as many steps.
    if (g.scene.solver.kind != SolverKind::kSteady) {
      g.scene.solver.end_time_s = (static_cast<double>(g.steps) + 0.5) * sim->dt_s();
    }
    return g;
  }
  // Every family's draws pass far more often than this (a packing too dense for its box is the
  // usual refusal): a generator that cannot make a scene is broken, and says so.
  throw std::runtime_error(
      fmt::format("GenerateScene({}): no valid scene in {} draws", seed, kMaxAttempts));
}

}  // namespace seep::core::metamorphic
