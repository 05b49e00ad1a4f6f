// LiveState: the live scene the effects act on, owned by the Stepper (docs/architecture.md §3,
// after OpenMM's Context: the context owns live data, a snapshot is a value).
//
// It holds only what several effects share: the particles, walls and DEM contact table, the
// current network and the positions it was detected from, the step's fluid books and the work
// counters. What one effect alone reads or writes lives in that effect (and, when it must survive
// a restart, in its part of the snapshot, effect_state.h).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/effects/fluid_ledger.h"
#include "seep/core/effects/fluid_vertices.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {

// Work done per effect, so a test can prove that an unlisted effect did nothing.
struct EffectCounters {
  DemCounters dem;                          // contacts, bonds, gravity, damping, integration, servo
  std::uint64_t pressure_force_passes = 0;  // AddPressureForces calls
  std::uint64_t volume_updates = 0;         // domain volumes recomputed from positions
  std::uint64_t aperture_updates = 0;       // apertures re-evaluated from contacts
  std::uint64_t flow_updates = 0;           // flow intervals solved
  std::uint64_t flow_sub_steps = 0;         // explicit sub-steps or implicit solves
  std::uint64_t topology_checks = 0;        // flow-contact sets compared with the network's
  std::uint64_t redetections = 0;           // domain re-detections (network rebuilds)
  std::uint64_t contact_detections = 0;     // cell-grid contact detections after set-up
  std::uint64_t injection_updates = 0;      // source rate (re)applied to the well domain
};

// The fluid's mass balance: the flow update and the pressure remap of a re-detection both write
// it, the time series and the report read it.
struct FluidBooks {
  double step_error = 0.0;   // relative error of the last flow update (its remap included)
  double worst_error = 0.0;  // the largest step_error of the run
  FluidLedger ledger;        // the cumulative books of the run (transient flow only)
};

struct LiveState {
  // The scene as it stands now: a scene with stages has the current stage's settings written into
  // it (run/stage_program.h), and effects re-read those in Effect::Reconfigure.
  const SceneSpec* scene = nullptr;
  // The run's storage model (RunStorage: the scene's volume and factor, the floor from the
  // network at set-up); every effect that weighs fluid uses this one.
  StorageModel storage;
  SceneNetwork net;  // domains, pipes and flow network of the current topology
  bool has_network = false;
  // Positions at the last (re-)detection of the network: the volume updater's reference.
  std::vector<double> detection_x, detection_y;
  std::uint64_t topology_version = 0;  // bumped at every re-detection
  // Mechanics (the contacts effect makes them; empty for a frozen packing).
  DemParticles particles;
  std::vector<DemWall> walls;
  // Per wall, what the pore fluid of the domains it closes does to it (the fluid forces effect
  // writes them, the walls effect's servo and report read them; 0 without fluid forces): the
  // normal force per m of thickness (> 0 compression, as contact loads), and the stiffness the
  // sealed pores oppose to its motion, sum K_f l^2 / V_s over them (the servo's gain needs it).
  std::vector<double> wall_pore_force;
  std::vector<double> wall_fluid_stiffness;
  // Per wall, its normal stress at the last step (the walls effect writes them; its report and the
  // stages' servo_held condition read them): total (contacts + pore pressure) and the contacts'
  // part alone (effective), Pa.
  std::vector<double> wall_stress_pa;
  std::vector<double> wall_effective_stress_pa;
  // The stress a servo on wall w holds (WallSpec::servo_effective_stress: the contacts' part
  // alone, else the total); 0 before the walls effect has measured it.
  double ServoStressPa(std::size_t w, bool effective) const {
    const std::vector<double>& stress = effective ? wall_effective_stress_pa : wall_stress_pa;
    return w < stress.size() ? stress[w] : 0.0;
  }
  std::optional<DemContactForces> contacts;
  FluidBooks books;
  EffectCounters counters;
  // Inside Stepper::Step, from the drift on: a number no other step had; 0 outside a step.
  std::uint64_t step_stamp = 0;
  std::uint64_t last_step_stamp = 0;  // the last one handed out
  // The particles and wall vertices of this step, copied once for the effects that read the
  // loops every step (FluidVertices::CurrentInStep; with walls in the fluid).
  FluidVertices step_vertices;

  bool moves() const { return contacts.has_value(); }
};

}  // namespace seep::core
