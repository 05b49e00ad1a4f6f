#include "seep/core/run/coupled_stepper.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>

#include "../effects/effect_factories.h"
#include "seep/core/dem/dem_integrator.h"
#include "seep/core/effects/registry.h"

namespace seep::core {

CoupledStepper::CoupledStepper(const SceneSpec& scene) : scene_(scene) { state_.scene = &scene_; }

Result<std::unique_ptr<CoupledStepper>> CoupledStepper::Create(const SceneSpec& scene,
                                                               SceneNetwork net, bool has_network) {
  std::unique_ptr<CoupledStepper> stepper(new CoupledStepper(scene));
  CoupledState& s = stepper->state_;
  s.net = std::move(net);
  s.has_network = has_network;
  s.detection_x = s.net.packing.x;
  s.detection_y = s.net.packing.y;
  stepper->effects_ = MakeEffects(stepper->scene_.effects);
  stepper->effect_seconds_.assign(stepper->effects_.size(), 0.0);
  for (std::size_t k = 0; k < stepper->effects_.size(); ++k) {
    Effect& effect = *stepper->effects_[k];
    SEEP_RETURN_IF_ERROR(effect.Bind(s));
    const std::uint32_t hooks = effect.Hooks();
    if (hooks & kForceHook) stepper->force_.push_back(k);
    if (hooks & kPostForceHook) stepper->post_force_.push_back(k);
    if (hooks & kEndOfStepHook) stepper->end_of_step_.push_back(k);
    if (effect.Name() == "flow") stepper->flow_effect_ = &effect;
  }
  if (stepper->force_.empty() || stepper->effects_[stepper->force_.front()]->Name() != "contacts") {
    return Internal("coupled step: the contacts effect must lead the force list");
  }
  if (HasEffect<FluidForcesEffectSpec>(scene) && HasEffect<VolumeChangeEffectSpec>(scene)) {
    // The pore fluid is a spring between the particles: the step must resolve it as well.
    const double safety = FindEffect<ContactsEffectSpec>(scene)->dt_safety;
    s.fluid_limited_dt = effects_internal::FluidStableStep(s, safety);
    // Contacts and fluid act on the same particles in parallel: their stiffnesses add, so
    // 1/dt^2 = 1/dt_contacts^2 + 1/dt_fluid^2 (taking the smaller alone let an undamped column
    // diverge at dt_safety 0.5).
    s.dem_dt = 1.0 / std::sqrt(1.0 / (s.dem_dt * s.dem_dt) +
                               1.0 / (s.fluid_limited_dt * s.fluid_limited_dt));
  }
  if (stepper->flow_effect_ != nullptr) {
    stepper->flow_every_ = effects_internal::FlowEverySteps(*stepper->flow_effect_, s);
  }
  SEEP_RETURN_IF_ERROR(stepper->InitialForces());
  return stepper;
}

std::vector<std::string_view> CoupledStepper::HookList(Hook hook) const {
  const std::vector<std::size_t>& list = hook == kForceHook       ? force_
                                         : hook == kPostForceHook ? post_force_
                                                                  : end_of_step_;
  std::vector<std::string_view> names;
  for (const std::size_t k : list) names.push_back(effects_[k]->Name());
  return names;
}

std::vector<double> CoupledStepper::ReportedPoreVolumes() const {
  MechanicsSnapshot snap;
  const auto pore = state_.net.flow.pore_volume();
  snap.pore_volume.assign(pore.begin(), pore.end());
  for (const auto& effect : effects_) effect->CompleteSnapshot(state_, &snap);
  return snap.pore_volume;
}

std::vector<std::pair<std::string_view, double>> CoupledStepper::EffectSeconds() const {
  std::vector<std::pair<std::string_view, double>> out;
  out.emplace_back("integration", integration_seconds_);
  for (std::size_t k = 0; k < effects_.size(); ++k) {
    out.emplace_back(effects_[k]->Name(), effect_seconds_[k]);
  }
  return out;
}

namespace {

using Clock = std::chrono::steady_clock;

// Runs one hook of one effect and adds its wall time to *seconds.
template <typename Call>
Status Timed(double* seconds, Call call) {
  const Clock::time_point start = Clock::now();
  const Status status = call();
  *seconds += std::chrono::duration<double>(Clock::now() - start).count();
  return status;
}

}  // namespace

Status CoupledStepper::InitialForces() {
  StepInfo info;
  info.dt = state_.dem_dt;
  for (const std::size_t k : force_) SEEP_RETURN_IF_ERROR(effects_[k]->AddForces(state_, info));
  for (const std::size_t k : post_force_) {
    SEEP_RETURN_IF_ERROR(effects_[k]->PostForce(state_, info));
  }
  return Status::Ok();
}

Status CoupledStepper::RebindAll() {
  for (const auto& effect : effects_) SEEP_RETURN_IF_ERROR(effect->Rebind(state_));
  return Status::Ok();
}

Status CoupledStepper::CheckParticlesFinite(std::uint64_t step) const {
  const DemParticles& p = state_.particles;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!std::isfinite(p.x[i]) || !std::isfinite(p.y[i])) {
      return FailedPrecondition(
          fmt::format("mechanics: particle {} left the finite numbers at step {}; lower "
                      "contacts.dt_safety or check the stiffness and the loads",
                      i, step));
    }
  }
  return Status::Ok();
}

Status CoupledStepper::Step(std::uint64_t step, std::uint64_t total_steps) {
  CoupledState& s = state_;
  const double dt = s.dem_dt;
  StepInfo info;
  info.step = step;
  info.time_s = static_cast<double>(step) * dt;
  info.dt = dt;
  if (flow_effect_ != nullptr && (step % flow_every_ == 0 || step == total_steps)) {
    const std::uint64_t interval_start = (step - 1) / flow_every_ * flow_every_;
    info.flow_update = true;
    info.flow_dt = static_cast<double>(step - interval_start) * dt;
  }
  Clock::time_point start = Clock::now();
  IntegrateFirstHalf(&s.particles, dt, &s.counters.dem);
  if (!s.walls.empty()) MoveWalls(&s.walls, dt);
  integration_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
  for (const std::size_t k : force_) {
    Effect& e = *effects_[k];
    SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return e.AddForces(s, info); }));
  }
  for (const std::size_t k : post_force_) {
    Effect& e = *effects_[k];
    SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return e.PostForce(s, info); }));
  }
  start = Clock::now();
  IntegrateSecondHalf(&s.particles, dt, &s.counters.dem);
  integration_seconds_ += std::chrono::duration<double>(Clock::now() - start).count();
  // A blow-up is caught within a flow interval, or 64 steps without flow, not with a pass over
  // the particles every step; it cannot hide: non-finite positions stay non-finite.
  if (info.flow_update || step % 64 == 0 || step == total_steps) {
    SEEP_RETURN_IF_ERROR(CheckParticlesFinite(step));
  }
  if (!info.flow_update) return Status::Ok();
  for (const std::size_t k : end_of_step_) {
    const std::uint64_t topology = s.topology_version;
    Effect& e = *effects_[k];
    SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return e.EndOfStep(s, info); }));
    if (s.topology_version != topology) {
      SEEP_RETURN_IF_ERROR(Timed(&effect_seconds_[k], [&] { return RebindAll(); }));
    }
  }
  if (s.injection_rate_m2_s > 0.0 && s.net.well_domain >= 0) {
    const double well = s.net.flow.pressure()[static_cast<std::size_t>(s.net.well_domain)];
    if (well > s.peak_well_pressure_pa) {
      s.peak_well_pressure_pa = well;
      s.peak_well_time_s = info.time_s;
    }
  }
  return Status::Ok();
}

void CoupledStepper::SaveTo(MechanicsSnapshot* out) const {
  const CoupledState& s = state_;
  const DemParticles& p = s.particles;
  out->x = p.x;
  out->y = p.y;
  out->vx = p.vx;
  out->vy = p.vy;
  out->omega = p.omega;
  out->fx = p.fx;
  out->fy = p.fy;
  out->torque = p.torque;
  out->walls.clear();
  for (const DemWall& w : s.walls) {
    out->walls.insert(out->walls.end(), {w.px, w.py, w.nx, w.ny, w.vx, w.vy});
  }
  out->contacts = s.contacts->SaveState();
  out->detection_x = s.detection_x;
  out->detection_y = s.detection_y;
  out->detection_i = s.net.contacts.i;
  out->detection_j = s.net.contacts.j;
  out->detection_gap = s.net.contacts.gap;
  if (s.has_network) {
    const auto apparent = s.net.flow.apparent_volume();
    const auto pore = s.net.flow.pore_volume();
    const auto aperture = s.net.flow.pipe_aperture();
    out->apparent_volume.assign(apparent.begin(), apparent.end());
    out->pore_volume.assign(pore.begin(), pore.end());
    out->aperture.assign(aperture.begin(), aperture.end());
  }
  out->bonds_broken = s.bonds_broken;
  out->topology_version = s.topology_version;
  out->peak_well_pressure_pa = s.peak_well_pressure_pa;
  out->peak_well_time_s = s.peak_well_time_s;
  out->worst_flow_mass_balance_error = s.flow.worst_mass_balance_error;
  out->max_flow_sub_steps = s.flow.max_sub_steps;
  out->breakthrough_time_s = s.breakthrough_time_s;
  for (const auto& effect : effects_) effect->CompleteSnapshot(s, out);
}

namespace {

Status CheckLength(const char* field, std::size_t got, std::size_t want) {
  if (got == want) return Status::Ok();
  return DataLoss(
      fmt::format("snapshot.mechanics.{}: {} values, this scene needs {}", field, got, want));
}

Status CheckFinite(const char* field, const std::vector<double>& v) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      return DataLoss(fmt::format("snapshot.mechanics.{}[{}]: not finite", field, i));
    }
  }
  return Status::Ok();
}

}  // namespace

Status CoupledStepper::RestoreFrom(const MechanicsSnapshot& snap) {
  CoupledState& s = state_;
  const std::size_t n = s.particles.size();
  const std::pair<const char*, const std::vector<double>*> fields[] = {
      {"x", &snap.x},
      {"y", &snap.y},
      {"vx", &snap.vx},
      {"vy", &snap.vy},
      {"omega", &snap.omega},
      {"fx", &snap.fx},
      {"fy", &snap.fy},
      {"torque", &snap.torque},
      {"detection_x", &snap.detection_x},
      {"detection_y", &snap.detection_y}};
  for (const auto& [name, values] : fields) {
    SEEP_RETURN_IF_ERROR(CheckLength(name, values->size(), n));
    SEEP_RETURN_IF_ERROR(CheckFinite(name, *values));
  }
  SEEP_RETURN_IF_ERROR(CheckLength("walls", snap.walls.size(), 6 * s.walls.size()));
  SEEP_RETURN_IF_ERROR(CheckFinite("walls", snap.walls));
  const std::size_t contacts = snap.detection_i.size();
  SEEP_RETURN_IF_ERROR(CheckLength("detection_j", snap.detection_j.size(), contacts));
  SEEP_RETURN_IF_ERROR(CheckLength("detection_gap", snap.detection_gap.size(), contacts));
  for (std::size_t c = 0; c < contacts; ++c) {
    const std::int32_t i = snap.detection_i[c], j = snap.detection_j[c];
    const bool sorted = c == 0 || snap.detection_i[c - 1] < i ||
                        (snap.detection_i[c - 1] == i && snap.detection_j[c - 1] < j);
    if (i < 0 || j <= i || static_cast<std::size_t>(j) >= n || !sorted) {
      return DataLoss(
          fmt::format("snapshot.mechanics.detection_i/j[{}]: ({}, {}) is not a sorted "
                      "pair of particles of this scene",
                      c, i, j));
    }
  }
  // The network of the detection, rebuilt exactly as the run built it.
  SceneNetwork net;
  if (s.has_network) {
    net.packing = s.net.packing;
    net.packing.x = snap.detection_x;
    net.packing.y = snap.detection_y;
    net.contacts.i = snap.detection_i;
    net.contacts.j = snap.detection_j;
    net.contacts.gap = snap.detection_gap;
    net.mean_radius_m = s.net.mean_radius_m;
    net.well_x_m = s.net.well_x_m;
    net.well_y_m = s.net.well_y_m;
    net.well_may_vanish = s.net.well_may_vanish;
    Result<SceneNetwork> built = ConnectSceneNetwork(scene_, std::move(net));
    if (!built.ok()) {
      return DataLoss("snapshot.mechanics.detection: " + built.status().message());
    }
    net = std::move(*built);
    SEEP_RETURN_IF_ERROR(
        CheckLength("apparent_volume", snap.apparent_volume.size(), net.flow.num_domains()));
    SEEP_RETURN_IF_ERROR(
        CheckLength("pore_volume", snap.pore_volume.size(), net.flow.num_domains()));
    SEEP_RETURN_IF_ERROR(CheckLength("aperture", snap.aperture.size(), net.flow.num_pipes()));
    SEEP_RETURN_IF_ERROR(CheckFinite("apparent_volume", snap.apparent_volume));
    SEEP_RETURN_IF_ERROR(CheckFinite("pore_volume", snap.pore_volume));
    SEEP_RETURN_IF_ERROR(CheckFinite("aperture", snap.aperture));
  }
  // Everything checked that can be without touching the state; the contact state checks itself.
  SEEP_RETURN_IF_ERROR(s.contacts->RestoreState(snap.contacts, n, s.walls.size()));
  DemParticles& p = s.particles;
  p.x = snap.x;
  p.y = snap.y;
  p.vx = snap.vx;
  p.vy = snap.vy;
  p.omega = snap.omega;
  p.fx = snap.fx;
  p.fy = snap.fy;
  p.torque = snap.torque;
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const double* v = &snap.walls[6 * w];
    s.walls[w] = DemWall{v[0], v[1], v[2], v[3], v[4], v[5]};
  }
  s.detection_x = snap.detection_x;
  s.detection_y = snap.detection_y;
  if (s.has_network) {
    s.net = std::move(net);
    if (!std::equal(snap.aperture.begin(), snap.aperture.end(),
                    s.net.flow.pipe_aperture().begin())) {
      SEEP_RETURN_IF_ERROR(s.net.flow.SetApertures(snap.aperture, scene_.fluid.viscosity_pa_s));
    }
    // Effects bind to the network as detected (the volume updater captures its rattler
    // correction from the detected volumes), then the volumes move on to the snapshot's.
    SEEP_RETURN_IF_ERROR(RebindAll());
    const std::size_t domains = s.net.domains.num_domains();
    if (!std::equal(snap.apparent_volume.begin(), snap.apparent_volume.end(),
                    s.net.flow.apparent_volume().begin())) {
      std::copy(snap.apparent_volume.begin(), snap.apparent_volume.end(),
                s.net.flow.mutable_apparent_volume().begin());
    }
    if (!std::equal(snap.pore_volume.begin(), snap.pore_volume.end(),
                    s.net.flow.pore_volume().begin())) {
      std::copy(snap.pore_volume.begin(), snap.pore_volume.end(),
                s.net.flow.mutable_pore_volume().begin());
    }
    std::copy(snap.apparent_volume.begin(), snap.apparent_volume.begin() + domains,
              s.net.domains.apparent_volume.begin());
    std::copy(snap.pore_volume.begin(), snap.pore_volume.begin() + domains,
              s.net.domains.pore_volume.begin());
  }
  s.bonds_broken = snap.bonds_broken;
  s.topology_version = snap.topology_version;
  s.peak_well_pressure_pa = snap.peak_well_pressure_pa;
  s.peak_well_time_s = snap.peak_well_time_s;
  s.flow.worst_mass_balance_error = snap.worst_flow_mass_balance_error;
  s.flow.max_sub_steps = snap.max_flow_sub_steps;
  s.breakthrough_time_s = snap.breakthrough_time_s;
  return Status::Ok();
}

}  // namespace seep::core
