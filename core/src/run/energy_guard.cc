#include "seep/core/run/energy_guard.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>

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

void EnergyGuard::Setup(const LiveState& s) {
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
}

void EnergyGuard::Start(const LiveState& s) {
  Setup(s);
  if (!active_) return;
  state_ = EnergyGuardState{};
  state_.initial_j = KineticEnergy(s.particles) + ContactEnergyBound(s);
  state_.gravity_moment_j = GravityMoment(s);
}

Status EnergyGuard::Validate(const EnergyGuardState& in) {
  for (const auto& [field, value] :
       {std::pair{"initial_j", in.initial_j}, std::pair{"gravity_moment_j", in.gravity_moment_j},
        std::pair{"work_j", in.work_j}, std::pair{"fluid_work_j", in.fluid_work_j}}) {
    if (!std::isfinite(value)) {
      return DataLoss(
          fmt::format("snapshot.mechanics.energy_guard.{}: must be finite (got {})", field, value));
    }
  }
  return Status::Ok();
}

void EnergyGuard::RestoreFrom(const std::optional<EnergyGuardState>& in, const LiveState& s) {
  if (!in) {
    Start(s);
    return;
  }
  Setup(s);
  state_ = *in;
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
    const double speed = wall.vx * wall.nx + wall.vy * wall.ny;
    if (speed == 0.0) continue;
    if (w < loads.size()) work += loads[w].normal_force * speed * dt;
  }
  // A held particle pushes the others with the reaction of what their contacts do to it (its
  // weight and its fluid forces act on it alone).
  const DemParticles& p = s.particles;
  const bool fluid = !before_fx_.empty();
  for (const std::uint32_t i : held_) {
    double fx = p.fx[i] - p.mass[i] * gravity_x_;
    double fy = p.fy[i] - p.mass[i] * gravity_y_;
    if (fluid) {
      fx -= p.fx[i] - before_fx_[i];
      fy -= p.fy[i] - before_fy_[i];
    }
    work -= (fx * p.vx[i] + fy * p.vy[i] + p.torque[i] * p.omega[i]) * dt;
  }
  state_.work_j += work;
}

void EnergyGuard::BeforeFluidForces(const LiveState& s) {
  if (!active_) return;
  before_fx_ = s.particles.fx;
  before_fy_ = s.particles.fy;
}

void EnergyGuard::AfterFluidForces(const LiveState& s, double dt) {
  if (!active_) return;
  const DemParticles& p = s.particles;
  double power = 0.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (p.fixed[i]) continue;
    power += (p.fx[i] - before_fx_[i]) * p.vx[i] + (p.fy[i] - before_fy_[i]) * p.vy[i];
  }
  state_.fluid_work_j += power * dt;
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
