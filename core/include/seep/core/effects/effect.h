// Effect: one physics contribution to the coupled step loop, and the live state effects act on
// (design-anchors §5.4, after LAMMPS fixes and their setmask()).
//
// An effect says once, through Hooks(), which points of the step it needs; the loop builds one
// list per hook at set-up and never rebuilds it, so an effect that is absent costs nothing and
// one that is present costs one call per hook per step. Hooks return Status: a numerical failure
// becomes a FAILED job with a message, never an abort.
//
// The step (CoupledStepper::Step, velocity-Verlet):
//   first half-kick and drift of the particles, walls move
//   kForce       contact forces (which set, not add), gravity, fluid pressure forces
//   kPostForce   local damping (needs the summed force), servo walls (need the wall loads)
//   second half-kick
//   kEndOfStep   at flow updates only: volume change, apertures, flow, re-detection, injection
#pragma once

#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <string_view>
#include <vector>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/dem/dem_counters.h"
#include "seep/core/dem/dem_particles.h"
#include "seep/core/dem/dem_wall.h"
#include "seep/core/geometry/packing.h"
#include "seep/core/network/scene_network.h"
#include "seep/core/spec/scene_spec.h"
#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/status.h"

namespace seep::core {

enum Hook : std::uint32_t {
  kForceHook = 1u << 0,
  kPostForceHook = 1u << 1,
  kEndOfStepHook = 1u << 2,
};

struct StepInfo {
  std::uint64_t step = 0;    // the step being taken (1-based)
  double time_s = 0.0;       // simulated time at its end
  double dt = 0.0;           // the DEM step, s
  bool flow_update = false;  // this step ends a flow interval
  double flow_dt = 0.0;      // the flow interval's length, s (when flow_update)
};

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

// What the last flow update measured (for the time series, the report and the log).
struct CoupledFlowReport {
  double mass_balance_error = 0.0;        // relative, of the flow update (remap included)
  double worst_mass_balance_error = 0.0;  // over the run
  std::int64_t last_sub_steps = 0;        // flow sub-steps in the last update
  std::int64_t max_sub_steps = 0;         // most flow sub-steps in one update
  double dt_crit_s = 0.0;                 // the explicit limit at the last update
  std::int32_t limiting_domain = -1;
};

// The live scene the effects act on. The Simulation owns it; effects keep only their own caches.
struct CoupledState {
  const SceneSpec* scene = nullptr;
  SceneNetwork net;  // domains, pipes and flow network of the current topology
  bool has_network = false;
  // Positions at the last (re-)detection of the network: the volume updater's reference.
  std::vector<double> detection_x, detection_y;
  // Mechanics (present when the contacts effect is listed).
  DemParticles particles;
  std::vector<DemWall> walls;
  std::optional<DemContactForces> contacts;
  double dem_dt = 0.0;
  // The step the pore fluid's stiffness alone allows (fluid_forces with volume_change), else
  // inf; the DEM step combines it with the contacts' (1/dt^2 adds).
  double fluid_limited_dt = std::numeric_limits<double>::infinity();
  // Servo walls: the loaded length and settings per wall (walls effect), for the report.
  std::vector<double> wall_stress_pa;  // measured normal stress per wall at the last step
  // dV per domain over the current flow interval (volume_change effect), empty = rigid.
  std::vector<double> volume_change;
  // Injection into the well domain (injection effect); 0 = none.
  double injection_rate_m2_s = 0.0;
  double peak_well_pressure_pa = 0.0;  // the breakdown pressure once the well pressure falls
  double peak_well_time_s = 0.0;
  // When a fracture first joined the well to the outside (radial scenes), else -1.
  double breakthrough_time_s = -1.0;
  // Bonds broken so far.
  std::uint64_t bonds_broken = 0;
  std::uint64_t topology_version = 0;  // bumped at every re-detection
  CoupledFlowReport flow;
  EffectCounters counters;
};

class Effect {
 public:
  virtual ~Effect() = default;
  virtual std::string_view Name() const = 0;
  virtual std::uint32_t Hooks() const = 0;
  // Validates against the scene and the other effects and prepares the state (walls, bonds,
  // the solver); runs once, in canonical order.
  virtual Status Bind(CoupledState& /*state*/) { return Status::Ok(); }
  // After a Restore replaced the state (or a re-detection replaced the network): refresh the
  // caches that depend on it.
  virtual Status Rebind(CoupledState& /*state*/) { return Status::Ok(); }
  virtual Status AddForces(CoupledState& /*state*/, const StepInfo& /*info*/) {
    return Status::Ok();
  }
  virtual Status PostForce(CoupledState& /*state*/, const StepInfo& /*info*/) {
    return Status::Ok();
  }
  virtual Status EndOfStep(CoupledState& /*state*/, const StepInfo& /*info*/) {
    return Status::Ok();
  }
  // Adds what the effect keeps current only for reports (not for the step) to a snapshot that
  // the stepper has filled from the state; reads and writes only the fields it owns (the
  // stepper also calls it on a snapshot holding just those, for a run's report).
  virtual void CompleteSnapshot(const CoupledState& /*state*/, MechanicsSnapshot* /*out*/) const {}
};

}  // namespace seep::core
