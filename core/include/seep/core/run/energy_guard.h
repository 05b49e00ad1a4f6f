// EnergyGuard: a moving scene's step checked on energy, so that an unstable step ends the run
// FAILED instead of shattering the sample silently (docs/guide/stability.md).
//
// A stable step can only lose the energy the disks were given: the contacts' dashpots, local
// damping, friction and breaking bonds take energy away, nothing makes it. So at every moment
//   K <= E_0 + W
//   K    the disks' kinetic energy (translation and spin);
//   E_0  K and the contacts' strain energy at the start, the latter bounded above by
//        sum F_n^2 / (2 k_n) + F_s^2 / (2 k_t) over disk and wall contacts (a bond is stiffer
//        than k_n, so this overestimates its share);
//   W    the work done on the disks since (each step by the trapezoid rule, exact for a spring):
//        by each wall's motion against its contacts' load, by held particles against their
//        contacts, by the pore fluid's forces (pressure and buoyancy, on every free disk) and by
//        gravity (the exact sum m_i g.(x_i - x_i0)).
// The pore fluid counts as a load from outside: what it gives the disks is work, whatever made its
// pressure (a reservoir, an injection, the pores' own compression). The contacts' strain energy
// now is left out of the left side (it is >= 0): the check costs one pass over the particles every
// kCheckEvery steps; the fluid's work two passes every step with fluid forces (no copy).
//
// An unstable step makes energy: its mode grows by a factor each step and soon exceeds any bound
// (the main example at dt_safety 1.0 holds 0.38 J/m at step 8, 3.5e6 times its floor, with nothing
// given: an unstable step's work sums are no longer the forces' work). The guard
// fails the run when
//   K > kAllowedRatio x (E_0 + W) + floor,
// floor the energy of every disk on one contact pressed by a millionth of its radius (a sample at
// rest has E_0 + W = 0 and K at rounding).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "seep/core/effects/live_state.h"
#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/status.h"

namespace seep::core {

class EnergyGuard {
 public:
  // Why the ratio: velocity-Verlet at a stable step shows a mode's kinetic energy up to
  // 1/(1 - (omega dt / 2)^2) of its true energy (x 2.8 at dt_safety 0.8 of a lone spring), and the
  // work is summed by the trapezoid rule; the examples and generated scenes stay below 1.05 (an
  // undamped, lossless one sits at 1: all it is given moves its disks)
  // (seep_stable_step_probe prints the ratio), an unstable step passes 10 within tens of steps.
  static constexpr double kAllowedRatio = 4.0;
  // Steps between two checks (and the last step): an unstable mode is caught within this many
  // steps of passing the bound.
  static constexpr std::uint64_t kCheckEvery = 8;

  // The start: E_0 from the state after the initial forces.
  void Start(const LiveState& s);
  // After the force hooks of a step (the walls' loads and the forces on held particles are this
  // step's, the walls' velocities those they moved with): the work of walls and held particles.
  void AddStepWork(const LiveState& s, double dt);
  // Around the fluid forces effect's AddForces (the initial forces' too, with dt 0): its forces are
  // what it adds, their work on the free disks (F_last + F) / 2 . v dt (v the step's half-kick
  // velocity: the drift this step made).
  void BeforeFluidForces(const LiveState& s);
  void AfterFluidForces(const LiveState& s, double dt);
  // OK, or FAILED_PRECONDITION naming the energies, the step and the settings to change.
  Status Check(const LiveState& s, std::uint64_t step, double dt_safety) const;
  // K / (E_0 + W + floor) now: the guard's headroom (the probe prints it).
  double Ratio(const LiveState& s) const;

  void SaveTo(EnergyGuardState* out) const { *out = state_; }
  // DATA_LOSS naming the first value of a snapshot's account that is not finite, or a force list
  // whose length does not fit this scene (walls, held particles, particles with fluid forces).
  Status Validate(const EnergyGuardState& in, const LiveState& s) const;
  // After the rest of a restore (Start ran at set-up): the snapshot's (validated) account; a
  // snapshot without one (written before the guard kept it) starts it again from the restored
  // state.
  void RestoreFrom(const std::optional<EnergyGuardState>& in, const LiveState& s);

 private:
  // E_0 + W now.
  double Budget(const LiveState& s) const;
  // Sum m_i g.x_i over the free particles (gravity's potential, with its sign reversed).
  double GravityMoment(const LiveState& s) const;
  // What the contacts do to held particle i: its force less its weight and its fluid force.
  void HeldContactForce(const LiveState& s, std::size_t i, double* fx, double* fy) const;

  bool active_ = false;
  double gravity_x_ = 0.0, gravity_y_ = 0.0;  // m/s^2
  double floor_j_ = 0.0;
  std::vector<std::uint32_t> held_;  // the held particles
  // Between BeforeFluidForces and AfterFluidForces: the last step's fluid forces' power at this
  // step's velocities, and whether there was no last step.
  double last_fluid_power_ = 0.0;
  bool first_fluid_pass_ = false;
  EnergyGuardState state_;
};

}  // namespace seep::core
