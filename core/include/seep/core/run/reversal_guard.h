// ReversalGuard: a moving scene's step checked for motion that reverses every step, so that a
// mode at velocity Verlet's limit, or a servo that overshoots its target each step, ends the run
// FAILED instead of breaking the sample or holding a wrong stress silently
// (docs/guide/stability.md).
//
// The energy guard (energy_guard.h) catches a mode that grows past what the disks were given. Two
// failures stay inside that budget:
//  - A bonded sample's fastest mode past Verlet's limit: the step estimate is one contact's, and a
//    disk held by six contacts and bonds is stiffer. The mode grows until bonds break, which
//    releases it, and sits at the limit from then on: hydraulic_fracturing at dt_safety 0.7 broke
//    352 bonds in 600 steps with its kinetic energy at 0.03-0.12 of its budget.
//  - A servo whose gain misses some of the stiffness it pushes (a platen's pore fluid once did):
//    it chatters between its speed limits and holds the wrong stress.
// Both are period-two motion, which physics at a resolved step does not make. A mode of velocity
// Verlet x(n) ~ lambda^n is stable for omega dt <= 2, where lambda = e^(i theta) with
// omega dt = 2 sin(theta / 2); the ratio of its step's velocity change to its mid-step velocity,
// |F dt / m| / |v(n - 1/2)|, is 2 sin(theta / 2) <= 2, and 1 + r > 2 for an unstable lambda = -r.
// The disks' reversal ratio, sum m |F dt / m|^2 over sum m |v(n - 1/2)|^2, is that squared and
// averaged over the modes by their energy: <= 4 for any stable motion, near 0.01 for a healthy
// run at dt_safety 0.5, 3.7-4.4 once a mode sits at the limit
// (seep_stable_step_probe prints it).
#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "seep/core/effects/live_state.h"
#include "seep/core/run/simulation_snapshot.h"
#include "seep/core/status.h"

namespace seep::core {

class ReversalGuard {
 public:
  // The disks: the run fails when the reversal ratio passes kDiskLimit at kDiskChecks checks in a
  // row (the energy guard's checks, every 8 steps). Why 3.5: a stable mode passes it only within
  // 7 % of the limit (omega dt > 1.87) and only while it holds most of the kinetic energy; two
  // checks, since a mode passing through the limit on its way to breaking bonds may fall back
  // below it for a check (hydraulic_fracturing at 0.75: 4.35, 4.71, 3.17 at steps 16-32).
  static constexpr double kDiskLimit = 3.5;
  static constexpr std::uint32_t kDiskChecks = 2;
  // A servo wall: fails when it has reversed its speed on each of kServoSteps steps in a row,
  // each time keeping at least kServoKeep of its speed (a servo that converges slows down) with
  // its stress more than kServoMiss of its target away (a servo at its target may dither).
  static constexpr std::uint32_t kServoSteps = 32;
  static constexpr double kServoKeep = 0.98;
  static constexpr double kServoMiss = 0.01;

  // The reversal ratio of the free disks after a step of dt (v their end velocities, F the step's
  // forces); 0 when nothing moves.
  static double DiskRatio(const DemParticles& p, double dt);

  // A wall's servo after one more step: whether it reversed (its speed against the last) without
  // slowing, while missing its target; the count of such steps in a row.
  static std::uint32_t ServoReversals(std::uint32_t so_far, double last_speed, double speed,
                                      double miss_fraction);

  void Start(const LiveState& s);
  // After the force hooks of a step: each wall's speed this step (the one its servo set last
  // step) against the last, with the stress it was set from.
  void AddStep(const LiveState& s);
  // At the energy guard's checks: OK, or FAILED_PRECONDITION naming the ratio or the wall, the
  // step and the setting to change.
  Status Check(const LiveState& s, std::uint64_t step, double dt, double dt_safety);

  void SaveTo(ReversalGuardState* out) const { *out = state_; }
  // DATA_LOSS when a snapshot's lists do not fit this scene's walls or a speed is not finite.
  Status Validate(const ReversalGuardState& in, const LiveState& s) const;
  // A snapshot without the guard's state (written before it was kept) starts it again.
  void RestoreFrom(const std::optional<ReversalGuardState>& in, const LiveState& s);

 private:
  bool active_ = false;
  ReversalGuardState state_;
};

}  // namespace seep::core
