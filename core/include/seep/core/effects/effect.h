// Effect: one physics contribution to the step loop (docs/architecture.md §4, after LAMMPS fixes
// and their setmask()).
//
// An effect says once, through Hooks(), which points of the step it needs; the loop builds one
// list per hook at set-up and never rebuilds it, so an effect that is absent costs nothing and
// one that is present costs one call per hook per step. Hooks return Status: a numerical failure
// becomes a FAILED job with a message, never an abort.
//
// The step (Stepper::Step; velocity-Verlet when the particles move):
//   first half-kick and drift of the particles, walls move
//   kFlowUpdate  at flow updates only: volume change, flow (the pressure of the positions the
//                forces then act at)
//   kForce       contacts (which set, not add), gravity, fluid pressure forces
//   kPostForce   local damping (needs the summed force), servo walls (need the wall loads)
//   second half-kick
//   kEndOfStep   at flow updates only: apertures (from this step's contact forces), re-detection,
//                injection
//
// Why the flow update precedes the forces: pressure that follows deformation is a spring between
// the particles, and a force that reads the pressure of the previous step's positions is a
// spring one step late. A delayed spring gains energy every step (by (omega dt)^2 / 2 of it in
// velocity-Verlet, at any step), which only damping hid: real water's bonded sample broke apart
// under confinement (seep_stable_step_probe shows the growth against the step).
//
// Besides its hooks an effect owns what it alone keeps: its caches, its run totals (saved and
// restored through its part of the snapshot, effect_state.h), its report metrics and its time
// series columns. Shared live data is in LiveState.
#pragma once

#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <vector>

#include "seep/core/effects/effect_state.h"
#include "seep/core/effects/live_state.h"
#include "seep/core/spec/effect_spec.h"
#include "seep/core/status.h"

namespace seep::core {

struct EffectSet;

enum Hook : std::uint32_t {
  kForceHook = 1u << 0,
  kPostForceHook = 1u << 1,
  kEndOfStepHook = 1u << 2,
  kFlowUpdateHook = 1u << 3,
};

struct StepInfo {
  std::uint64_t step = 0;    // the step being taken (1-based)
  double time_s = 0.0;       // simulated time at its end
  double dt = 0.0;           // the step, s
  bool flow_update = false;  // this step ends a flow interval
  double flow_dt = 0.0;      // the flow interval's length, s (when flow_update)
};

// Named report measurements, sorted by name.
using Metrics = std::map<std::string, double>;

class Effect {
 public:
  explicit Effect(std::size_t kind) : kind_(kind) {}
  virtual ~Effect() = default;
  Effect(const Effect&) = delete;
  Effect& operator=(const Effect&) = delete;

  std::size_t kind() const { return kind_; }  // the EffectSpec arm
  std::string_view Name() const { return EffectName(kind_); }
  virtual std::uint32_t Hooks() const = 0;

  // Validates against the scene and prepares the state (walls, bonds, the solver); runs once, in
  // canonical order. `effects` gives the typed handles of the other listed effects.
  virtual Status Bind(LiveState& /*state*/, const EffectSet& /*effects*/) { return Status::Ok(); }
  // After a restore replaced the state (or a re-detection replaced the network): refresh the
  // caches that depend on it.
  virtual Status Rebind(LiveState& /*state*/) { return Status::Ok(); }
  // The settings a stage controls changed in *state.scene (a stage began, or a schedule moved;
  // run/stage_program.h): take them up. Must be idempotent — setting the same values twice leaves
  // the state as once — since a restore re-applies the settings of the moment it resumes at.
  virtual Status Reconfigure(LiveState& /*state*/) { return Status::Ok(); }
  virtual Status UpdateFlow(LiveState& /*state*/, const StepInfo& /*info*/) { return Status::Ok(); }
  virtual Status AddForces(LiveState& /*state*/, const StepInfo& /*info*/) { return Status::Ok(); }
  virtual Status PostForce(LiveState& /*state*/, const StepInfo& /*info*/) { return Status::Ok(); }
  virtual Status EndOfStep(LiveState& /*state*/, const StepInfo& /*info*/) { return Status::Ok(); }

  // The effect's own run totals into / out of its part of a snapshot (effect_state.h).
  virtual void SaveTo(EffectStates* /*out*/) const {}
  virtual void RestoreFrom(const EffectStates& /*in*/) {}

  // What the effect measures, for the run report and the time series (one value per column).
  virtual void AddMetrics(const LiveState& /*state*/, Metrics* /*out*/) const {}
  virtual void AddSeriesColumns(const LiveState& /*state*/,
                                std::vector<std::string>* /*columns*/) const {}
  virtual void AddSample(const LiveState& /*state*/, std::vector<double>* /*row*/) const {}

 private:
  std::size_t kind_;
};

// An effect that keeps its spec: its kind follows from the spec's type.
template <typename Spec>
class EffectWithSpec : public Effect {
 public:
  explicit EffectWithSpec(const Spec& spec) : Effect(kEffectKind<Spec>), spec_(spec) {}

 protected:
  Spec spec_;
};

}  // namespace seep::core
