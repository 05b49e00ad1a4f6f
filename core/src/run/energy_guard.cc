#include "seep/core/run/energy_guard.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <tuple>

namespace seep::core {
namespace {

// An upper bound of the strain energy the contacts hold: F_n^2 / (2 k_n) + F_s^2 / (2 k_t) each.
double ContactEnergyBound(const LiveState& s) {
  const ContactLawParams& law = FindEffect<ContactsEffectSpec>(*s.scene)->law;
  const auto spring = [&](double fn, double fs) {
    return fn * fn / (2.0 * law.kn) + (law.kt > 0.0 ? fs * fs / (2.0 * law.kt) : 0.0);
  };
  double energy = 0.0;
  std::vector<DemContactRecord> pairs;
  s.contacts->CollectContacts(&pairs);
  for (const DemContactRecord& c : pairs) energy += spring(c.normal_force, c.shear_force);
  std::vector<DemWallContactRecord> walls;
  s.contacts->CollectWallContacts(&walls);
  for (const DemWallContactRecord& c : walls) energy += spring(c.normal_force, c.shear_force);
  return energy;
}

}  // namespace

void EnergyGuard::Start(const LiveState& s) {
  // What follows from the scene alone: gravity, the held particles, the floor.
  active_ = s.moves();
  if (!active_) return;
  if (const auto* gravity = FindEffect<GravityEffectSpec>(*s.scene)) {
    gravity_x_ = gravity->gx_m_s2;
    gravity_y_ = gravity->gy_m_s2;
  }
  const DemParticles& p = s.particles;
  held_.clear();
  double radius_sum = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.fixed[i]) held_.push_back(static_cast<std::uint32_t>(i));
    radius_sum += p.radius[i];
  }
  const double n = static_cast<double>(p.size());
  const double nudge = 1e-6 * (n > 0.0 ? radius_sum / n : 0.0);
  floor_j_ = n * 0.5 * FindEffect<ContactsEffectSpec>(*s.scene)->law.kn * nudge * nudge;
  // The account.
  state_.initial_j = KineticEnergy(s.particles) + ContactEnergyBound(s);
  state_.gravity_moment_j = GravityMoment(s);
  state_.work_j = 0.0;
  state_.fluid_work_j = 0.0;
  const std::vector<DemWallLoad>& loads = s.contacts->wall_loads();
  state_.wall_load.assign(s.walls.size(), 0.0);
  for (std::size_t w = 0; w < s.walls.size() && w < loads.size(); ++w) {
    state_.wall_load[w] = loads[w].normal_force;
  }
  state_.held_fx.assign(held_.size(), 0.0);
  state_.held_fy.assign(held_.size(), 0.0);
  for (std::size_t k = 0; k < held_.size(); ++k) {
    HeldContactForce(s, held_[k], &state_.held_fx[k], &state_.held_fy[k]);
  }
  // The fluid's forces at the start were taken around the initial forces (fluid_fx, fluid_fy).
}

Status EnergyGuard::Validate(const EnergyGuardState& in, const LiveState& s) const {
  for (const auto& [field, value] :
       {std::pair{"initial_j", in.initial_j}, std::pair{"gravity_moment_j", in.gravity_moment_j},
        std::pair{"work_j", in.work_j}, std::pair{"fluid_work_j", in.fluid_work_j}}) {
    if (!std::isfinite(value)) {
      return DataLoss(
          fmt::format("snapshot.mechanics.energy_guard.{}: must be finite (got {})", field, value));
    }
  }
  const std::size_t held = held_.size();  // set up at Start, for this scene
  const std::size_t fluid = FindEffect<FluidForcesEffectSpec>(*s.scene) ? s.particles.size() : 0;
  for (const auto& [field, values, size] :
       {std::tuple{"wall_load", &in.wall_load, s.walls.size()},
        std::tuple{"held_fx", &in.held_fx, held}, std::tuple{"held_fy", &in.held_fy, held},
        std::tuple{"fluid_fx", &in.fluid_fx, fluid}, std::tuple{"fluid_fy", &in.fluid_fy, fluid}}) {
    if (values->size() != size) {
      return DataLoss(
          fmt::format("snapshot.mechanics.energy_guard.{}: {} values, this scene has {}", field,
                      values->size(), size));
    }
    for (const double v : *values) {
      if (!std::isfinite(v)) {
        return DataLoss(
            fmt::format("snapshot.mechanics.energy_guard.{}: must be finite (got {})", field, v));
      }
    }
  }
  return Status::Ok();
}

void EnergyGuard::RestoreFrom(const std::optional<EnergyGuardState>& in, const LiveState& s) {
  if (!in) {
    // A checkpoint written before the guard kept its account: it starts from here, and its first
    // step takes the fluid's forces without work (the ones it holds are the set-up's).
    Start(s);
    state_.fluid_fx.clear();
    state_.fluid_fy.clear();
    return;
  }
  state_ = *in;  // the rest was set up at Start, for this scene
}

void EnergyGuard::HeldContactForce(const LiveState& s, std::size_t i, double* fx,
                                   double* fy) const {
  const DemParticles& p = s.particles;
  *fx = p.fx[i] - p.mass[i] * gravity_x_;
  *fy = p.fy[i] - p.mass[i] * gravity_y_;
  if (!state_.fluid_fx.empty()) {
    *fx -= state_.fluid_fx[i];
    *fy -= state_.fluid_fy[i];
  }
}

void EnergyGuard::AddStepWork(const LiveState& s, double dt) {
  if (!active_) return;
  double work = 0.0;
  // A wall moves along its normal (servo or velocity control) and pushes the disks with its
  // contacts' load (what it does to the pore fluid is the fluid's business: its forces on the
  // disks are counted as they act); a fixed wall does no work.
  const std::vector<DemWallLoad>& loads = s.contacts->wall_loads();
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const DemWall& wall = s.walls[w];
    const double load = w < loads.size() ? loads[w].normal_force : 0.0;
    const double speed = wall.vx * wall.nx + wall.vy * wall.ny;
    work += 0.5 * (state_.wall_load[w] + load) * speed * dt;
    state_.wall_load[w] = load;
  }
  // A held particle pushes the others with the reaction of what their contacts do to it (its
  // weight and its fluid forces act on it alone).
  const DemParticles& p = s.particles;
  for (std::size_t k = 0; k < held_.size(); ++k) {
    const std::uint32_t i = held_[k];
    double fx = 0.0, fy = 0.0;
    HeldContactForce(s, i, &fx, &fy);
    work -= (0.5 * (state_.held_fx[k] + fx) * p.vx[i] + 0.5 * (state_.held_fy[k] + fy) * p.vy[i] +
             p.torque[i] * p.omega[i]) *
            dt;
    state_.held_fx[k] = fx;
    state_.held_fy[k] = fy;
  }
  state_.work_j += work;
}

// The last step's fluid forces are read once (their power at this step's velocity) and their slots
// then hold minus the forces so far, so that the effect's forces are what its pass adds to them:
// no copy of the force arrays.
void EnergyGuard::BeforeFluidForces(const LiveState& s) {
  const DemParticles& p = s.particles;
  first_fluid_pass_ = state_.fluid_fx.size() != p.size();
  if (first_fluid_pass_) {
    state_.fluid_fx.assign(p.size(), 0.0);
    state_.fluid_fy.assign(p.size(), 0.0);
  }
  double power = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!p.fixed[i]) power += state_.fluid_fx[i] * p.vx[i] + state_.fluid_fy[i] * p.vy[i];
    state_.fluid_fx[i] = -p.fx[i];
    state_.fluid_fy[i] = -p.fy[i];
  }
  last_fluid_power_ = power;
}

void EnergyGuard::AfterFluidForces(const LiveState& s, double dt) {
  const DemParticles& p = s.particles;
  double power = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    state_.fluid_fx[i] += p.fx[i];
    state_.fluid_fy[i] += p.fy[i];
    if (!p.fixed[i]) power += state_.fluid_fx[i] * p.vx[i] + state_.fluid_fy[i] * p.vy[i];
  }
  if (!first_fluid_pass_) state_.fluid_work_j += 0.5 * (last_fluid_power_ + power) * dt;
}

double EnergyGuard::Budget(const LiveState& s) const {
  return state_.initial_j + state_.work_j + state_.fluid_work_j +
         (GravityMoment(s) - state_.gravity_moment_j);
}

double EnergyGuard::Ratio(const LiveState& s) const {
  if (!active_) return 0.0;
  return KineticEnergy(s.particles) / (std::max(Budget(s), 0.0) + floor_j_);
}

Status EnergyGuard::Check(const LiveState& s, std::uint64_t step, double dt_safety) const {
  if (!active_) return Status::Ok();
  const double kinetic = KineticEnergy(s.particles);
  const double budget = std::max(Budget(s), 0.0);
  if (kinetic <= kAllowedRatio * budget + floor_j_) return Status::Ok();
  return FailedPrecondition(fmt::format(
      "stability: at step {} the disks' kinetic energy ({:.4g} J/m) is {:.3g} times what they "
      "were given (their energy at the start and the work of walls, gravity and pore fluid since: "
      "{:.4g} J/m; a stable step stays below {} times): the step is unstable; lower "
      "contacts.dt_safety (now {}) or raise the damping (contacts.law.damping_ratio, "
      "local_damping.alpha)",
      step, kinetic, kinetic / (budget + floor_j_), budget, kAllowedRatio, dt_safety));
}

double EnergyGuard::GravityMoment(const LiveState& s) const {
  if (gravity_x_ == 0.0 && gravity_y_ == 0.0) return 0.0;
  const DemParticles& p = s.particles;
  double sum = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.fixed[i]) continue;
    sum += p.mass[i] * (gravity_x_ * p.x[i] + gravity_y_ * p.y[i]);
  }
  return sum;
}

}  // namespace seep::core
