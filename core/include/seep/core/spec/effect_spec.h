// EffectSpec: the physics a scene switches on, one struct per effect (docs/architecture.md §4).
//
// A scene lists its effects; an effect that is not listed is never constructed and costs nothing.
// An empty list means what every scene meant before effects existed: pipe flow on a frozen
// packing (the `flow` effect alone), with no contact detection after set-up.
//
// The variant's arm order is the canonical execution order: within each hook of the step loop
// the effects run in this order whatever order the scene lists them in, so a scene's result does
// not depend on how its author sorted the list. Adding an effect: a spec struct here (and its arm
// in the variant at the place its hooks must run), a class in core/src/effects/, one arm in
// registry.cc (a missing arm is a compile error), one oneof arm in scene.proto plus its codec case.
#pragma once

#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <string_view>
#include <type_traits>
#include <variant>
#include <vector>

#include "seep/core/dem/contact_law.h"
#include "seep/core/dem/parallel_bond.h"

namespace seep::core {

// The particles move: DEM contacts (disk-disk and disk-wall linear spring-dashpot with Coulomb
// friction) and velocity-Verlet integration. Every other mechanical effect requires it.
struct ContactsEffectSpec {
  ContactLawParams law;        // kn, kt in N/m per m of thickness; gamma_n 1/s
  double density_kg_m3 = 0.0;  // disk density, kg/m^3 (mass per unit thickness = rho pi R^2)
  double skin_m = 0.0;         // Verlet skin; 0 = one tenth of the mean radius
  // DEM step as a fraction of the stable estimate sqrt(m/kn) (dem_integrator.h), in (0, 1].
  double dt_safety = 0.2;
};

// Parallel bonds between every pair whose gap is at most tolerance_m at set-up.
struct BondsEffectSpec {
  BondParams params;
  double tolerance_m = 0.0;
};

struct GravityEffectSpec {
  double gx_m_s2 = 0.0;
  double gy_m_s2 = -9.81;
};

// Fluid pressure -> forces on the particles around each domain (chord rule, docs/physics.md §2.5).
struct FluidForcesEffectSpec {};

// PFC local damping, alpha in [0, 1).
struct LocalDampingEffectSpec {
  double alpha = 0.7;
};

enum class WallSide { kLeft, kRight, kBottom, kTop };

// "left", "right", "bottom", "top": how reports and series name a wall.
constexpr const char* WallSideName(WallSide side) {
  switch (side) {
    case WallSide::kLeft:
      return "left";
    case WallSide::kRight:
      return "right";
    case WallSide::kBottom:
      return "bottom";
    case WallSide::kTop:
      return "top";
  }
  return "unknown";
}

// A drained wall: a porous platen behind which the fluid is held at pressure_pa. Each stretch of
// the wall that closes a domain is a pipe of conductance conductance_m_per_pa_s x its length into
// the platen's reservoir (q = C (P_wall - P_domain), m^2/s per m of thickness).
struct WallDrainSpec {
  double pressure_pa = std::numeric_limits<double>::quiet_NaN();  // required
  double conductance_m_per_pa_s = 0.0;                            // > 0
};

// A wall given by its end points instead of a side: the segment from (x0, y0) to (x1, y1), its
// normal on the left of the direction of travel (the side a servo or a velocity pushes towards).
// Disks touch its nearest point and pass beyond its ends (dem_wall.h).
struct WallSegmentSpec {
  double x0_m = 0.0, y0_m = 0.0, x1_m = 0.0, y1_m = 0.0;
};

// A rigid wall on one side of the packing's bounding box, touching its outermost disk, or the
// segment `segment`; with servo_stress_pa > 0 its speed is servo-controlled to hold that normal
// stress (servo_wall.h), with normal_velocity_m_s it moves at that speed along its normal
// (strain-controlled loading; > 0 towards the side the normal points to: inwards for a side
// wall). With flow, a side wall bounds the fluid (docs/physics.md §2.4 option B): the pores along
// it are domains closed by it, it is impermeable unless drained, and the pore pressure of those
// domains pushes on it (segment walls are refused with flow: the fluid's walls are lines). The
// servo holds the total stress (contacts + pore pressure) unless servo_effective_stress asks for
// the contacts' stress alone.
struct WallSpec {
  WallSide side = WallSide::kBottom;  // ignored when `segment` is set
  double servo_stress_pa = 0.0;       // 0 = fixed wall
  double servo_gain_fraction = 0.5;
  double servo_max_speed_m_s = 0.0;    // > 0 for a servo wall
  std::optional<WallDrainSpec> drain;  // unset: impermeable
  bool servo_effective_stress = false;
  // (Last, so that code listing the fields above in order still means the same wall.)
  std::optional<WallSegmentSpec> segment;     // set: the wall is this segment
  std::optional<double> normal_velocity_m_s;  // set: velocity-controlled (not with a servo)
};

// A fixed wall on `side`, or a servo wall when servo_stress_pa > 0; impermeable, servo on the
// total stress (what code that builds scenes, tests and benches, starts from).
inline WallSpec SideWall(WallSide side, double servo_stress_pa = 0.0,
                         double servo_gain_fraction = 0.5, double servo_max_speed_m_s = 0.0) {
  WallSpec w;
  w.side = side;
  w.servo_stress_pa = servo_stress_pa;
  w.servo_gain_fraction = servo_gain_fraction;
  w.servo_max_speed_m_s = servo_max_speed_m_s;
  return w;
}

// A fixed wall from (x0, y0) to (x1, y1), the particles on the left of the direction of travel.
inline WallSpec SegmentWall(double x0, double y0, double x1, double y1) {
  WallSpec w;
  w.segment = WallSegmentSpec{x0, y0, x1, y1};
  return w;
}

// How reports and series name wall k: its side, or "segment<k>" for a segment wall.
std::string WallName(const WallSpec& wall, std::size_t k);

// The same wall, drained into a reservoir at pressure_pa.
inline WallSpec Drained(WallSpec wall, double pressure_pa, double conductance_m_per_pa_s) {
  wall.drain = WallDrainSpec{pressure_pa, conductance_m_per_pa_s};
  return wall;
}

struct WallsEffectSpec {
  std::vector<WallSpec> walls;
};

// Deformation -> dV term of the pressure update (eq. 4): domain volumes refreshed from the moving
// particles at every flow update.
struct VolumeChangeEffectSpec {};

// Contact forces and gaps -> pipe apertures (scene.aperture law) at every flow update.
struct ApertureUpdateEffectSpec {};

// Pipe flow on the network with the scene's solver (explicit sub-cycled or implicit; steady
// scenes only without mechanics).
struct FlowEffectSpec {
  // DEM steps per flow update; 0 = automatic: 1 when the fluid's step is the smaller (the fluid
  // is sub-cycled inside the DEM step), else the whole number of DEM steps that fits in
  // solver.dt_factor x dt_crit of the initial network and in the step the fluid's stiffness
  // allows (a lagging pressure is a delayed spring).
  std::uint32_t every_steps = 0;
};

// Topology change (bond break, contact lost or made) -> domains re-detected and pressures
// remapped conserving the stored fluid (docs/physics.md §2.6, V16), checked at every flow update.
struct RedetectionEffectSpec {};

// Constant-rate injection into the domain that contains the well centre (radial scenes): that
// domain becomes a source instead of a fixed-pressure well. Follows the well through merges.
struct InjectionEffectSpec {
  double rate_m2_s = 0.0;  // > 0
};

using EffectSpec = std::variant<ContactsEffectSpec, BondsEffectSpec, GravityEffectSpec,
                                FluidForcesEffectSpec, LocalDampingEffectSpec, WallsEffectSpec,
                                VolumeChangeEffectSpec, ApertureUpdateEffectSpec, FlowEffectSpec,
                                RedetectionEffectSpec, InjectionEffectSpec>;

inline constexpr std::size_t kEffectKinds = std::variant_size_v<EffectSpec>;

namespace effect_spec_internal {
template <typename T, typename Variant>
struct ArmIndex;
template <typename T, typename... Arms>
struct ArmIndex<T, std::variant<Arms...>> {
  static constexpr std::size_t value = [] {
    std::size_t i = 0;
    (void)((std::is_same_v<T, Arms> ? false : (++i, true)) && ...);
    return i;
  }();
};
}  // namespace effect_spec_internal

// The arm of EffectSpec that holds Spec: an effect's kind, the key of its name and its order.
template <typename Spec>
inline constexpr std::size_t kEffectKind = effect_spec_internal::ArmIndex<Spec, EffectSpec>::value;

// The name a scene file and messages use for the arm (e.g. "fluid_forces").
std::string_view EffectName(std::size_t kind);
inline std::string_view EffectName(const EffectSpec& spec) { return EffectName(spec.index()); }

}  // namespace seep::core
