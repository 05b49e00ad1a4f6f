#include <cmath>
#include <limits>
#include <string>
#include <utility>

#include "fmt/format.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {

bool HasFluidWeight(const SceneSpec& scene) {
  return scene.fluid.density_kg_m3 > 0.0 && HasEffect<GravityEffectSpec>(scene);
}

namespace {

// Largest packings a scene may generate or carry; a bound keeps a typo from exhausting memory.
constexpr std::uint64_t kMaxParticles = 20'000'000;

Status RequirePositive(const char* field, double value) {
  if (!std::isfinite(value) || value <= 0.0) {
    return InvalidArgument(
        fmt::format("scene.{}: must be a finite number > 0 (got {})", field, value));
  }
  // A subnormal quantity's inverse overflows to inf (a lattice of 5e-324 m disks made the contact
  // grid's cell width infinite and took seepd down): no physical quantity of a scene is one.
  if (!std::isnormal(value)) {
    return InvalidArgument(
        fmt::format("scene.{}: must be at least {} (the smallest normal double; got {})", field,
                    std::numeric_limits<double>::min(), value));
  }
  return Status::Ok();
}

Status RequireNonNegative(const char* field, double value) {
  if (!std::isfinite(value) || value < 0.0) {
    return InvalidArgument(
        fmt::format("scene.{}: must be a finite number >= 0 (got {})", field, value));
  }
  return Status::Ok();
}

Status RequireFinite(const char* field, double value) {
  if (!std::isfinite(value)) {
    return InvalidArgument(fmt::format("scene.{}: must be finite (got {})", field, value));
  }
  return Status::Ok();
}

Status ValidateLattice(const LatticePackingSpec& lattice) {
  if (lattice.columns < 2) {
    return InvalidArgument(fmt::format(
        "scene.packing.lattice.columns: needs at least 2 disks to enclose a domain (got {})",
        lattice.columns));
  }
  if (lattice.rows < 2) {
    return InvalidArgument(fmt::format(
        "scene.packing.lattice.rows: needs at least 2 disks to enclose a domain (got {})",
        lattice.rows));
  }
  if (std::uint64_t{lattice.columns} * lattice.rows > kMaxParticles) {
    return InvalidArgument(
        fmt::format("scene.packing.lattice: {} x {} disks exceed the limit of {}", lattice.columns,
                    lattice.rows, kMaxParticles));
  }
  return RequirePositive("packing.lattice.radius_m", lattice.radius_m);
}

Status ValidateRandom(const RandomPackingSpec& random) {
  SEEP_RETURN_IF_ERROR(RequirePositive("packing.random.width_m", random.width_m));
  SEEP_RETURN_IF_ERROR(RequirePositive("packing.random.height_m", random.height_m));
  SEEP_RETURN_IF_ERROR(RequirePositive("packing.random.min_radius_m", random.min_radius_m));
  SEEP_RETURN_IF_ERROR(RequirePositive("packing.random.max_radius_m", random.max_radius_m));
  if (random.max_radius_m < random.min_radius_m) {
    return InvalidArgument(
        fmt::format("scene.packing.random.max_radius_m: must be >= min_radius_m ({} < {})",
                    random.max_radius_m, random.min_radius_m));
  }
  const bool by_porosity = random.target_porosity != 0.0;
  const bool by_coordination = random.target_coordination != 0.0;
  if (by_porosity == by_coordination) {
    return InvalidArgument(
        "scene.packing.random.target: set exactly one of target_porosity and target_coordination");
  }
  if (by_porosity && !(random.target_porosity > 0.0 && random.target_porosity < 1.0)) {
    return InvalidArgument(
        fmt::format("scene.packing.random.target_porosity: must lie in (0, 1) (got {})",
                    random.target_porosity));
  }
  if (by_coordination && !(random.target_coordination > 0.0 && random.target_coordination < 6.0)) {
    return InvalidArgument(
        fmt::format("scene.packing.random.target_coordination: must lie in (0, 6) (got {})",
                    random.target_coordination));
  }
  if (random.particle_count < 3 || random.particle_count > kMaxParticles) {
    return InvalidArgument(
        fmt::format("scene.packing.random.particle_count: must lie in [3, {}] (got {})",
                    kMaxParticles, random.particle_count));
  }
  return Status::Ok();
}

Status ValidateParticles(const ParticleListSpec& list) {
  const std::size_t n = list.x_m.size();
  if (n < 3) {
    return InvalidArgument(fmt::format(
        "scene.packing.particles: needs at least 3 particles to enclose a domain (got {})", n));
  }
  if (n > kMaxParticles) {
    return InvalidArgument(fmt::format(
        "scene.packing.particles: {} particles exceed the limit of {}", n, kMaxParticles));
  }
  if (list.y_m.size() != n || list.radius_m.size() != n) {
    return InvalidArgument(fmt::format(
        "scene.packing.particles: x_m, y_m and radius_m must have equal lengths (got {}, {}, {})",
        n, list.y_m.size(), list.radius_m.size()));
  }
  for (std::size_t i = 0; i < n; ++i) {
    if (!std::isfinite(list.x_m[i]) || !std::isfinite(list.y_m[i])) {
      return InvalidArgument(
          fmt::format("scene.packing.particles[{}]: position must be finite (got {}, {})", i,
                      list.x_m[i], list.y_m[i]));
    }
    if (!std::isfinite(list.radius_m[i]) || list.radius_m[i] <= 0.0) {
      return InvalidArgument(
          fmt::format("scene.packing.particles[{}].radius_m: must be a finite number > 0 (got {})",
                      i, list.radius_m[i]));
    }
    if (!std::isnormal(list.radius_m[i])) {
      return InvalidArgument(fmt::format(
          "scene.packing.particles[{}].radius_m: must be at least {} (the smallest normal "
          "double; got {})",
          i, std::numeric_limits<double>::min(), list.radius_m[i]));
    }
  }
  return Status::Ok();
}

struct PackingSourceValidator {
  Status operator()(const LatticePackingSpec& s) const { return ValidateLattice(s); }
  Status operator()(const RandomPackingSpec& s) const { return ValidateRandom(s); }
  Status operator()(const ParticleListSpec& s) const { return ValidateParticles(s); }
};

// What only a scene with pipe flow uses: the fluid, the apertures, the boundary's pressures and
// the flow solver's settings. A DEM-only scene (contacts without flow) leaves them unset.
Status ValidateFlowSettings(const SceneSpec& scene) {
  if (!HasFlow(scene)) {
    // Unset (0) in a DEM-only scene; a value given must still be a number in range.
    const std::pair<const char*, double> given[] = {
        {"fluid.viscosity_pa_s", scene.fluid.viscosity_pa_s},
        {"fluid.bulk_modulus_pa", scene.fluid.bulk_modulus_pa},
        {"fluid.density_kg_m3", scene.fluid.density_kg_m3},
        {"aperture.residual_aperture_m", scene.aperture.residual_aperture_m},
        {"aperture.reference_force_n", scene.aperture.reference_force_n},
        {"aperture.gap_multiplier", scene.aperture.gap_multiplier},
        {"aperture.max_aperture_m", scene.aperture.max_aperture_m},
        {"solver.dt_factor", scene.solver.dt_factor}};
    for (const auto& [field, value] : given) SEEP_RETURN_IF_ERROR(RequireNonNegative(field, value));
    return Status::Ok();
  }
  SEEP_RETURN_IF_ERROR(RequirePositive("fluid.viscosity_pa_s", scene.fluid.viscosity_pa_s));
  SEEP_RETURN_IF_ERROR(RequirePositive("fluid.bulk_modulus_pa", scene.fluid.bulk_modulus_pa));
  SEEP_RETURN_IF_ERROR(RequireNonNegative("fluid.density_kg_m3", scene.fluid.density_kg_m3));
  SEEP_RETURN_IF_ERROR(
      RequirePositive("aperture.residual_aperture_m", scene.aperture.residual_aperture_m));
  SEEP_RETURN_IF_ERROR(
      RequireNonNegative("aperture.reference_force_n", scene.aperture.reference_force_n));
  SEEP_RETURN_IF_ERROR(
      RequireNonNegative("aperture.gap_multiplier", scene.aperture.gap_multiplier));
  SEEP_RETURN_IF_ERROR(
      RequireNonNegative("aperture.max_aperture_m", scene.aperture.max_aperture_m));
  if (scene.aperture.max_aperture_m > 0.0 &&
      scene.aperture.max_aperture_m < scene.aperture.residual_aperture_m) {
    return InvalidArgument(fmt::format(
        "scene.aperture.max_aperture_m: must be 0 (no cap) or >= residual_aperture_m ({} < {})",
        scene.aperture.max_aperture_m, scene.aperture.residual_aperture_m));
  }
  SEEP_RETURN_IF_ERROR(
      RequireFinite("boundary.inlet_pressure_pa", scene.boundary.inlet_pressure_pa));
  SEEP_RETURN_IF_ERROR(
      RequireFinite("boundary.outlet_pressure_pa", scene.boundary.outlet_pressure_pa));
  SEEP_RETURN_IF_ERROR(
      RequireFinite("boundary.initial_pressure_pa", scene.boundary.initial_pressure_pa));
  SEEP_RETURN_IF_ERROR(
      RequireFinite("boundary.initial_pressure_x_m", scene.boundary.initial_pressure_x_m));
  SEEP_RETURN_IF_ERROR(
      RequireFinite("boundary.initial_pressure_y_m", scene.boundary.initial_pressure_y_m));
  if (scene.boundary.initial_pressure_hydrostatic && !HasFluidWeight(scene)) {
    return InvalidArgument(
        "scene.boundary.initial_pressure_hydrostatic: needs a fluid with weight "
        "(fluid.density_kg_m3 > 0 and a gravity effect); without it the initial pressure is "
        "uniform anyway");
  }
  if (const auto& radial = scene.boundary.radial) {
    SEEP_RETURN_IF_ERROR(RequirePositive("boundary.radial.well_radius_m", radial->well_radius_m));
    SEEP_RETURN_IF_ERROR(RequirePositive("boundary.radial.outer_radius_m", radial->outer_radius_m));
    if (radial->outer_radius_m <= radial->well_radius_m) {
      return InvalidArgument(
          fmt::format("scene.boundary.radial.outer_radius_m: must be > well_radius_m ({} <= {})",
                      radial->outer_radius_m, radial->well_radius_m));
    }
    SEEP_RETURN_IF_ERROR(
        RequireFinite("boundary.radial.well_pressure_pa", radial->well_pressure_pa));
    SEEP_RETURN_IF_ERROR(
        RequireFinite("boundary.radial.outer_pressure_pa", radial->outer_pressure_pa));
  }
  if (const double f = scene.solver.storage_factor; !(std::isfinite(f) && f > 0.0 && f <= 1.0)) {
    return InvalidArgument(fmt::format(
        "scene.solver.storage_factor: must lie in (0, 1] (the fraction of the storage volume that "
        "holds fluid; got {})",
        f));
  }
  if (const double a = scene.solver.storage_floor_fraction;
      !(std::isfinite(a) && a >= 0.0 && a < 1.0)) {
    return InvalidArgument(fmt::format(
        "scene.solver.storage_floor_fraction: must lie in [0, 1) (the floor as a fraction of the "
        "mean storage volume; 0.05-0.2 is usual; got {})",
        a));
  }
  if (scene.solver.kind != SolverKind::kSteady) {
    SEEP_RETURN_IF_ERROR(RequirePositive("solver.dt_factor", scene.solver.dt_factor));
    if (scene.solver.kind == SolverKind::kExplicit && scene.solver.dt_factor > 1.0) {
      return InvalidArgument(fmt::format(
          "scene.solver.dt_factor: the explicit solver is unstable above the critical step; use a "
          "value in (0, 1] or the implicit solver (got {})",
          scene.solver.dt_factor));
    }
  }
  if (scene.boundary.closed_inlet && scene.boundary.radial) {
    return InvalidArgument(
        "scene.boundary.closed_inlet: applies to a linear boundary only (this one is radial)");
  }
  if (scene.boundary.walls_only) {
    if (scene.boundary.radial || scene.boundary.closed_inlet) {
      return InvalidArgument(
          "scene.boundary: a walls-only boundary has no radial part and no closed inlet");
    }
    if (FindEffect<WallsEffectSpec>(scene) == nullptr) {
      return InvalidArgument(
          "scene.boundary.axis: must be set (FLOW_AXIS_X or FLOW_AXIS_Y) or boundary.radial given; "
          "only a scene with a walls effect can leave both unset (the walls then bound the fluid)");
    }
  }
  return Status::Ok();
}

}  // namespace

Status ValidateScene(const SceneSpec& scene) {
  SEEP_RETURN_IF_ERROR(std::visit(PackingSourceValidator{}, scene.packing.source));
  SEEP_RETURN_IF_ERROR(RequireNonNegative("packing.contact_gap_m", scene.packing.contact_gap_m));
  SEEP_RETURN_IF_ERROR(ValidateFlowSettings(scene));
  if (scene.solver.kind != SolverKind::kSteady && scene.stages.empty()) {
    // With stages each stage ends on its own (ValidateStages requires end_time_s = 0).
    SEEP_RETURN_IF_ERROR(RequirePositive("solver.end_time_s", scene.solver.end_time_s));
  }
  SEEP_RETURN_IF_ERROR(ValidateEffects(scene));
  SEEP_RETURN_IF_ERROR(ValidateBoundaryRegions(scene));
  return ValidateStages(scene);
}

}  // namespace seep::core
