#include "seep/core/run/reversal_guard.h"

#include <fmt/format.h>

#include <cmath>

namespace seep::core {

double ReversalGuard::DiskRatio(const DemParticles& p, double dt) {
  double change = 0.0, motion = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.fixed[i]) continue;
    // The step's velocity change, and the velocity at its middle (before its second half kick).
    const double dvx = p.fx[i] * dt * p.inv_mass[i], dvy = p.fy[i] * dt * p.inv_mass[i];
    const double dw = p.torque[i] * dt * p.inv_inertia[i];
    const double vx = p.vx[i] - 0.5 * dvx, vy = p.vy[i] - 0.5 * dvy, w = p.omega[i] - 0.5 * dw;
    change += p.mass[i] * (dvx * dvx + dvy * dvy) + p.inertia[i] * dw * dw;
    motion += p.mass[i] * (vx * vx + vy * vy) + p.inertia[i] * w * w;
  }
  return motion > 0.0 ? change / motion : 0.0;
}

std::uint32_t ReversalGuard::ServoReversals(std::uint32_t so_far, double last_speed, double speed,
                                            double miss_fraction) {
  const bool reversed = speed * last_speed < 0.0 &&
                        std::abs(speed) >= kServoKeep * std::abs(last_speed) &&
                        miss_fraction > kServoMiss;
  return reversed ? so_far + 1 : 0;
}

void ReversalGuard::Start(const LiveState& s) {
  active_ = s.moves();
  state_ = ReversalGuardState{};
  state_.wall_speed.assign(s.walls.size(), 0.0);
  state_.wall_reversals.assign(s.walls.size(), 0);
}

void ReversalGuard::AddStep(const LiveState& s) {
  if (!active_) return;
  const auto* walls = FindEffect<WallsEffectSpec>(*s.scene);
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const DemWall& wall = s.walls[w];
    const double speed = wall.vx * wall.nx + wall.vy * wall.ny;
    std::uint32_t reversals = 0;
    if (walls != nullptr && w < walls->walls.size() && walls->walls[w].servo_stress_pa > 0.0) {
      const WallSpec& spec = walls->walls[w];
      const double miss =
          std::abs(s.ServoStressPa(w, spec.servo_effective_stress) - spec.servo_stress_pa) /
          spec.servo_stress_pa;
      reversals = ServoReversals(state_.wall_reversals[w], state_.wall_speed[w], speed, miss);
    }
    state_.wall_reversals[w] = reversals;
    state_.wall_speed[w] = speed;
  }
}

Status ReversalGuard::Check(const LiveState& s, std::uint64_t step, double dt, double dt_safety) {
  if (!active_) return Status::Ok();
  const auto* walls = FindEffect<WallsEffectSpec>(*s.scene);
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    if (state_.wall_reversals[w] < kServoSteps || walls == nullptr) continue;
    const WallSpec& spec = walls->walls[w];
    return FailedPrecondition(fmt::format(
        "stability: at step {} the servo of wall {} ({}) has reversed it on each of the last {} "
        "steps without slowing (now {:.4g} m/s), its {} stress {:.6g} Pa against a target of "
        "{:.6g} Pa: the servo overshoots every step; lower walls[{}].servo_gain_fraction (now {}) "
        "or contacts.dt_safety (now {})",
        step, w, WallName(spec, w), state_.wall_reversals[w], state_.wall_speed[w],
        spec.servo_effective_stress ? "effective" : "total",
        s.ServoStressPa(w, spec.servo_effective_stress), spec.servo_stress_pa, w,
        spec.servo_gain_fraction, dt_safety));
  }
  const double ratio = DiskRatio(s.particles, dt);
  state_.disk_checks = ratio > kDiskLimit ? state_.disk_checks + 1 : 0;
  if (state_.disk_checks < kDiskChecks) return Status::Ok();
  return FailedPrecondition(fmt::format(
      "stability: at step {} the disks' velocities reverse from one step to the next (reversal "
      "ratio {:.3g}, above {} at {} checks in a row; any stable motion stays below 4, a healthy "
      "run near 0.01): their fastest mode is at velocity Verlet's limit, which a disk held by "
      "several contacts and bonds reaches below the one-contact step; lower contacts.dt_safety "
      "(now {})",
      step, ratio, kDiskLimit, state_.disk_checks, dt_safety));
}

Status ReversalGuard::Validate(const ReversalGuardState& in, const LiveState& s) const {
  if (in.wall_speed.size() != s.walls.size() || in.wall_reversals.size() != s.walls.size()) {
    return DataLoss(fmt::format(
        "snapshot.mechanics.reversal_guard: {} wall speeds and {} reversal counts, this scene has "
        "{} walls",
        in.wall_speed.size(), in.wall_reversals.size(), s.walls.size()));
  }
  for (const double v : in.wall_speed) {
    if (!std::isfinite(v)) {
      return DataLoss(
          fmt::format("snapshot.mechanics.reversal_guard.wall_speed: must be finite (got {})", v));
    }
  }
  return Status::Ok();
}

void ReversalGuard::RestoreFrom(const std::optional<ReversalGuardState>& in, const LiveState& s) {
  if (!in) {
    Start(s);
    return;
  }
  state_ = *in;
}

}  // namespace seep::core
