// SceneSpec: a validated, immutable description of one simulation, in core types.
//
// It mirrors seep.v1.Scene field for field (service/codec converts between them). SI units, per
// unit out-of-plane thickness. Validate() is the domain check: it names the failing field by its
// path in the scene ("scene.fluid.viscosity_pa_s: must be > 0 (got -1)").
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <variant>
#include <vector>

#include "seep/core/flow/fluid.h"
#include "seep/core/flow/linear_solver_kind.h"
#include "seep/core/spec/boundary_region.h"
#include "seep/core/spec/effect_spec.h"
#include "seep/core/spec/stage_spec.h"
#include "seep/core/status.h"

namespace seep::core {

enum class LatticeKind { kSquare, kHex };

struct LatticePackingSpec {
  LatticeKind kind = LatticeKind::kSquare;
  std::uint32_t columns = 0;
  std::uint32_t rows = 0;
  double radius_m = 0.0;
};

struct RandomPackingSpec {
  std::uint64_t seed = 0;
  double width_m = 0.0;
  double height_m = 0.0;
  double min_radius_m = 0.0;
  double max_radius_m = 0.0;
  std::uint32_t particle_count = 0;
  // Exactly one target is > 0: the radii grow until the box porosity falls to target_porosity,
  // or until the mean number of contacts per particle reaches target_coordination.
  double target_porosity = 0.0;
  double target_coordination = 0.0;
};

struct ParticleListSpec {
  std::vector<double> x_m;
  std::vector<double> y_m;
  std::vector<double> radius_m;
};

using PackingSource = std::variant<LatticePackingSpec, RandomPackingSpec, ParticleListSpec>;

struct PackingSpec {
  PackingSource source;
  double contact_gap_m = 0.0;
};

struct FluidSpec {
  double viscosity_pa_s = 1e-3;
  double bulk_modulus_pa = 2.2e9;
  // rho_f, kg/m^3; 0 = the fluid has no weight. The weight acts only with a gravity effect
  // (which gives g): the pipes are then driven by the head, P - rho_f g.x, and the particles
  // are buoyed (docs/guide/fluid-weight.md, network/fluid_weight.h). Without a gravity effect a
  // density changes nothing.
  double density_kg_m3 = 0.0;
};

struct ApertureLawSpec {
  double residual_aperture_m = 0.0;
  double reference_force_n = 0.0;
  double gap_multiplier = 0.0;
  double max_aperture_m = 0.0;  // 0 = no cap
};

enum class FlowAxis { kX, kY };

// Radial flow around a borehole (docs/physics.md §2.4 "injection", §3.3). The sample is cut to an
// annulus about the centre of the particles' bounding box: particles whose centre lies closer
// than well_radius_m or farther than outer_radius_m are removed. The void face left in the middle
// is the well domain, held at well_pressure_pa; the contacts on the remaining outer hull are pipes
// to an outer reservoir at outer_pressure_pa.
struct RadialBoundarySpec {
  double well_radius_m = 0.0;
  double outer_radius_m = 0.0;
  double well_pressure_pa = 0.0;
  double outer_pressure_pa = 0.0;
};

// Linear (permeameter) by default: inlet and outlet reservoirs at the two ends along `axis`, the
// other sides no-flow. With `radial` set the boundary is radial and axis, inlet_pressure_pa and
// outlet_pressure_pa are unused.
struct BoundarySpec {
  FlowAxis axis = FlowAxis::kX;
  double inlet_pressure_pa = 0.0;
  double outlet_pressure_pa = 0.0;
  double initial_pressure_pa = 0.0;
  std::optional<RadialBoundarySpec> radial;
  // Linear only: the inlet end is a no-flow base (e.g. the undrained bottom of a consolidation
  // column); fluid leaves through the outlet end only and inlet_pressure_pa is unused.
  bool closed_inlet = false;
  // Neither linear nor radial: the walls alone bound the fluid (needs a walls effect); fluid
  // enters or leaves only through drained walls, and with none the sample is sealed.
  bool walls_only = false;
  // With fluid weight: the free domains start at rest, P = initial_pressure_pa + rho_f g.(x -
  // x_ref) at their centroids, initial_pressure_pa being the pressure at the reference point
  // (initial_pressure_x_m, initial_pressure_y_m). Needs fluid weight (validated).
  bool initial_pressure_hydrostatic = false;
  double initial_pressure_x_m = 0.0;
  double initial_pressure_y_m = 0.0;
  // Fixed pressures or fluxes on the domains inside shapes, on top of the boundary above (any
  // kind): boundary_region.h, network/boundary_regions.h.
  std::vector<BoundaryRegionSpec> regions;
};

// kImplicit is backward Euler; kCrankNicolson the theta = 1/2 method (second order, oscillates
// above a few dt_crit after sharp changes).
enum class SolverKind { kSteady, kExplicit, kImplicit, kCrankNicolson };

struct SolverSpec {
  SolverKind kind = SolverKind::kSteady;
  StorageVolume storage = StorageVolume::kPore;  // which volume stores fluid (flow/fluid.h)
  double dt_factor = 0.9;
  double end_time_s = 0.0;
  std::uint64_t progress_every = 0;
  // V_s = storage_factor x the storage volume (docs/physics.md §1.2 reading (b)): lets a 2D
  // packing's pores carry a real material's porosity (n_target / n_2D). In (0, 1].
  double storage_factor = 1.0;
  // Volume floor (docs/physics.md §4.4): V_s >= storage_floor_fraction x the mean V_s of the free
  // domains of the network at set-up, so slivers neither stall the explicit step nor blow up. In
  // [0, 1); 0 = none.
  double storage_floor_fraction = 0.0;
  // The factorization of the implicit and steady solves (flow/linear_solver_kind.h). CHOLMOD
  // supernodal unless the scene asks: a scene's results depend on it.
  LinearSolverKind linear_solver = LinearSolverKind::kCholmodSupernodal;
};

struct SceneSpec {
  std::string name;
  PackingSpec packing;
  FluidSpec fluid;
  ApertureLawSpec aperture;
  BoundarySpec boundary;
  SolverSpec solver;
  // The physics switched on (effect_spec.h); empty = flow on a frozen packing.
  std::vector<EffectSpec> effects;
  // The experiment's stages, run in order (stage_spec.h); empty = one stage from t = 0 to
  // solver.end_time_s. With stages solver.end_time_s stays 0: each stage ends on its own.
  std::vector<StageSpec> stages;
};

// Whether the scene lists an effect of type T.
template <typename T>
bool HasEffect(const SceneSpec& scene) {
  for (const EffectSpec& e : scene.effects) {
    if (std::holds_alternative<T>(e)) return true;
  }
  return false;
}

template <typename T>
const T* FindEffect(const SceneSpec& scene) {
  for (const EffectSpec& e : scene.effects) {
    if (const T* t = std::get_if<T>(&e)) return t;
  }
  return nullptr;
}

// The particles move: the scene lists the contacts effect (the coupled step loop runs).
inline bool HasMechanics(const SceneSpec& scene) { return HasEffect<ContactsEffectSpec>(scene); }
// The scene solves pipe flow (an empty effect list means flow alone).
inline bool HasFlow(const SceneSpec& scene) {
  return scene.effects.empty() || HasEffect<FlowEffectSpec>(scene);
}
// The fluid has weight: a density > 0 and a gravity effect (FluidSpec::density_kg_m3).
bool HasFluidWeight(const SceneSpec& scene);

// The storage model the scene's solver uses: its storage volume and factor (the floor depends on
// the network: RunStorage in network/scene_network.h).
inline StorageModel SceneStorage(const SceneSpec& scene) {
  StorageModel storage;
  storage.volume = scene.solver.storage;
  storage.factor = scene.solver.storage_factor;
  return storage;
}

// The effects' own fields and how they combine (core/src/effects/effect_validation.cc): each
// effect at most once; every mechanical effect needs `contacts`; the fluid couplings need both
// `contacts` and `flow`; a moving scene needs a transient solver. Messages name the list entry:
// "scene.effects[2].gravity: requires the contacts effect (the particles do not move without it)".
Status ValidateEffects(const SceneSpec& scene);

// The stages (stage_validation.cc): each setting against the effects and boundary it changes,
// each end condition against the effect it watches ("scene.stages[1].end[0].bonds_broken: the
// scene does not list the bonds effect"), every stage bounded, and solver.end_time_s unset.
Status ValidateStages(const SceneSpec& scene);

// The boundary regions (boundary_region_validation.cc): names, shapes, finite conditions, and no
// two regions whose shapes overlap with different conditions, in the scene or in any stage
// ("scene.boundary.regions[3] ('b'): overlaps regions[1] ('a') with a different condition; ...").
Status ValidateBoundaryRegions(const SceneSpec& scene);

// Checks every field against its physical range. The first violation is returned; its message
// starts with the field path.
Status ValidateScene(const SceneSpec& scene);

}  // namespace seep::core
