#include "scene_codec.h"

#include <fmt/format.h>

#include "codec/effect_codec.h"
#include "codec/region_codec.h"
#include "codec/stage_codec.h"
#include "codec/state_size_estimate.h"

namespace seep::service {
namespace {

using core::InvalidArgument;
using core::Result;

// A run reports its progress at least this often (in steps). Any interval up to it is fine: the
// time series keeps at most core::Stepper::kMaxSeriesRows rows whatever the interval.
constexpr std::uint64_t kMaxProgressEvery = 1'000'000'000;

Result<core::PackingSource> PackingFromProto(const v1::Packing& packing) {
  switch (packing.source_case()) {
    case v1::Packing::kLattice: {
      const auto& l = packing.lattice();
      core::LatticePackingSpec spec;
      switch (l.kind()) {
        case v1::LATTICE_KIND_SQUARE:
          spec.kind = core::LatticeKind::kSquare;
          break;
        case v1::LATTICE_KIND_HEX:
          spec.kind = core::LatticeKind::kHex;
          break;
        default:
          return InvalidArgument(
              fmt::format("scene.packing.lattice.kind: must be LATTICE_KIND_SQUARE or "
                          "LATTICE_KIND_HEX (got {})",
                          v1::LatticeKind_Name(l.kind())));
      }
      spec.columns = l.columns();
      spec.rows = l.rows();
      spec.radius_m = l.radius_m();
      return core::PackingSource(spec);
    }
    case v1::Packing::kRandom: {
      const auto& r = packing.random();
      core::RandomPackingSpec spec;
      spec.seed = r.seed();
      spec.width_m = r.width_m();
      spec.height_m = r.height_m();
      spec.min_radius_m = r.min_radius_m();
      spec.max_radius_m = r.max_radius_m();
      spec.particle_count = r.particle_count();
      switch (r.target_case()) {
        case v1::RandomPacking::kTargetPorosity:
          spec.target_porosity = r.target_porosity();
          break;
        case v1::RandomPacking::kTargetCoordination:
          spec.target_coordination = r.target_coordination();
          break;
        case v1::RandomPacking::TARGET_NOT_SET:
          return InvalidArgument(
              "scene.packing.random.target: one of target_porosity or target_coordination is "
              "required");
      }
      return core::PackingSource(spec);
    }
    case v1::Packing::kParticles: {
      const auto& p = packing.particles();
      core::ParticleListSpec list;
      list.x_m.assign(p.x_m().begin(), p.x_m().end());
      list.y_m.assign(p.y_m().begin(), p.y_m().end());
      list.radius_m.assign(p.radius_m().begin(), p.radius_m().end());
      return core::PackingSource(std::move(list));
    }
    case v1::Packing::SOURCE_NOT_SET:
      break;
  }
  return InvalidArgument("scene.packing: one of lattice, random or particles is required");
}

// Whether the scene solves pipe flow: an empty effect list (flow alone) or one with flow.
bool ListsFlow(const v1::Scene& scene) {
  if (scene.effects_size() == 0) return true;
  for (const v1::Effect& e : scene.effects()) {
    if (e.has_flow()) return true;
  }
  return false;
}

// `flow`: the scene solves pipe flow. Without it (a DEM-only scene) the solver's kind and storage
// mean nothing and may be left unset: the DEM step comes from the contacts, the end from
// end_time_s.
Result<core::SolverSpec> SolverFromProto(const v1::Solver& solver, bool flow) {
  core::SolverSpec spec;
  switch (flow || solver.kind() != v1::SOLVER_KIND_UNSPECIFIED ? solver.kind()
                                                               : v1::SOLVER_KIND_EXPLICIT) {
    case v1::SOLVER_KIND_STEADY:
      spec.kind = core::SolverKind::kSteady;
      break;
    case v1::SOLVER_KIND_EXPLICIT:
      spec.kind = core::SolverKind::kExplicit;
      break;
    case v1::SOLVER_KIND_IMPLICIT:
      spec.kind = core::SolverKind::kImplicit;
      break;
    case v1::SOLVER_KIND_CRANK_NICOLSON:
      spec.kind = core::SolverKind::kCrankNicolson;
      break;
    default:
      return InvalidArgument(
          fmt::format("scene.solver.kind: must be SOLVER_KIND_STEADY, SOLVER_KIND_EXPLICIT, "
                      "SOLVER_KIND_IMPLICIT or SOLVER_KIND_CRANK_NICOLSON (got {})",
                      v1::SolverKind_Name(solver.kind())));
  }
  switch (solver.storage()) {
    case v1::STORAGE_VOLUME_APPARENT:
      spec.storage = core::StorageVolume::kApparent;
      break;
    case v1::STORAGE_VOLUME_PORE:
      spec.storage = core::StorageVolume::kPore;
      break;
    default:
      // The steady state does not depend on storage, so only transient solvers need it.
      if (flow && spec.kind != core::SolverKind::kSteady) {
        return InvalidArgument(
            fmt::format("scene.solver.storage: a transient solver needs STORAGE_VOLUME_APPARENT or "
                        "STORAGE_VOLUME_PORE (got {})",
                        v1::StorageVolume_Name(solver.storage())));
      }
  }
  spec.dt_factor = solver.dt_factor();
  spec.end_time_s = solver.end_time_s();
  if (solver.progress_every() > kMaxProgressEvery) {
    return InvalidArgument(fmt::format(
        "scene.solver.progress_every: at most {} steps between progress reports (got {}); 0 "
        "chooses about 200 reports per run",
        kMaxProgressEvery, solver.progress_every()));
  }
  spec.progress_every = solver.progress_every();
  spec.storage_factor = solver.has_storage_factor() ? solver.storage_factor() : 1.0;
  spec.storage_floor_fraction = solver.storage_floor_fraction();
  switch (solver.linear_solver()) {
    case v1::LINEAR_SOLVER_UNSPECIFIED:  // as every scene before the choice: results unchanged
    case v1::LINEAR_SOLVER_CHOLMOD_SUPERNODAL:
      spec.linear_solver = core::LinearSolverKind::kCholmodSupernodal;
      break;
    case v1::LINEAR_SOLVER_SIMPLICIAL_LDLT:
      spec.linear_solver = core::LinearSolverKind::kEigenSimplicialLdlt;
      break;
    case v1::LINEAR_SOLVER_AUTO:
      spec.linear_solver = core::LinearSolverKind::kAuto;
      break;
    default:
      return InvalidArgument(
          fmt::format("scene.solver.linear_solver: must be LINEAR_SOLVER_CHOLMOD_SUPERNODAL, "
                      "LINEAR_SOLVER_SIMPLICIAL_LDLT or LINEAR_SOLVER_AUTO, or unset (got {})",
                      static_cast<int>(solver.linear_solver())));
  }
  return spec;
}

Result<core::BoundarySpec> BoundaryFromProto(const v1::Boundary& boundary) {
  core::BoundarySpec spec;
  spec.initial_pressure_pa = boundary.initial_pressure_pa();
  spec.initial_pressure_hydrostatic = boundary.initial_pressure_hydrostatic();
  spec.initial_pressure_x_m = boundary.initial_pressure_x_m();
  spec.initial_pressure_y_m = boundary.initial_pressure_y_m();
  if (boundary.has_radial()) {
    if (boundary.axis() != v1::FLOW_AXIS_UNSPECIFIED) {
      return InvalidArgument(
          fmt::format("scene.boundary.axis: must be unset with a radial boundary (got {})",
                      v1::FlowAxis_Name(boundary.axis())));
    }
    if (boundary.inlet_pressure_pa() != 0.0 || boundary.outlet_pressure_pa() != 0.0) {
      return InvalidArgument(fmt::format(
          "scene.boundary.inlet_pressure_pa: inlet and outlet pressures must be unset with a "
          "radial boundary (got {} and {}); use radial.well_pressure_pa and "
          "radial.outer_pressure_pa",
          boundary.inlet_pressure_pa(), boundary.outlet_pressure_pa()));
    }
    if (boundary.closed_inlet()) {
      return InvalidArgument(
          "scene.boundary.closed_inlet: applies to a linear boundary only (this one is radial)");
    }
    const v1::RadialBoundary& radial = boundary.radial();
    spec.radial = core::RadialBoundarySpec{radial.well_radius_m(), radial.outer_radius_m(),
                                           radial.well_pressure_pa(), radial.outer_pressure_pa()};
    return spec;
  }
  switch (boundary.axis()) {
    case v1::FLOW_AXIS_X:
      spec.axis = core::FlowAxis::kX;
      break;
    case v1::FLOW_AXIS_Y:
      spec.axis = core::FlowAxis::kY;
      break;
    case v1::FLOW_AXIS_UNSPECIFIED:
      // Neither linear nor radial: the walls bound the fluid (validation checks there are walls).
      if (boundary.inlet_pressure_pa() != 0.0 || boundary.outlet_pressure_pa() != 0.0 ||
          boundary.closed_inlet()) {
        return InvalidArgument(
            "scene.boundary.axis: must be FLOW_AXIS_X or FLOW_AXIS_Y with inlet or outlet "
            "pressures or closed_inlet (unset, the walls alone bound the fluid)");
      }
      spec.walls_only = true;
      return spec;
    default:
      return InvalidArgument(fmt::format(
          "scene.boundary.axis: must be FLOW_AXIS_X or FLOW_AXIS_Y, or set boundary.radial (got "
          "{})",
          v1::FlowAxis_Name(boundary.axis())));
  }
  spec.inlet_pressure_pa = boundary.inlet_pressure_pa();
  spec.outlet_pressure_pa = boundary.outlet_pressure_pa();
  spec.closed_inlet = boundary.closed_inlet();
  return spec;
}

}  // namespace

Result<core::SceneSpec> DecodeScene(const v1::Scene& scene) {
  core::SceneSpec spec;
  spec.name = scene.name();
  SEEP_ASSIGN_OR_RETURN(spec.packing.source, PackingFromProto(scene.packing()));
  spec.packing.contact_gap_m = scene.packing().contact_gap_m();
  spec.fluid = {scene.fluid().viscosity_pa_s(), scene.fluid().bulk_modulus_pa(),
                scene.fluid().density_kg_m3()};
  spec.aperture = {scene.aperture().residual_aperture_m(), scene.aperture().reference_force_n(),
                   scene.aperture().gap_multiplier(), scene.aperture().max_aperture_m()};
  SEEP_ASSIGN_OR_RETURN(spec.boundary, BoundaryFromProto(scene.boundary()));
  for (int k = 0; k < scene.boundary().regions_size(); ++k) {
    SEEP_RETURN_IF_ERROR(AppendRegionFromProto(
        scene.boundary().regions(k), static_cast<std::size_t>(k), &spec.boundary.regions));
  }
  SEEP_ASSIGN_OR_RETURN(spec.solver, SolverFromProto(scene.solver(), ListsFlow(scene)));
  for (int k = 0; k < scene.effects_size(); ++k) {
    SEEP_RETURN_IF_ERROR(
        AppendEffectFromProto(scene.effects(k), static_cast<std::size_t>(k), &spec.effects));
  }
  for (int k = 0; k < scene.stages_size(); ++k) {
    SEEP_RETURN_IF_ERROR(
        AppendStageFromProto(scene.stages(k), static_cast<std::size_t>(k), &spec.stages));
  }
  return spec;
}

Result<core::SceneSpec> SceneFromProto(const v1::Scene& scene) {
  SEEP_ASSIGN_OR_RETURN(core::SceneSpec spec, DecodeScene(scene));
  SEEP_RETURN_IF_ERROR(core::ValidateScene(spec));
  SEEP_RETURN_IF_ERROR(CheckStateFitsACheckpoint(spec));
  return spec;
}

}  // namespace seep::service
