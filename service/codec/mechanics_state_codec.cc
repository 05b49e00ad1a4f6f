#include "codec/mechanics_state_codec.h"

#include <string>

namespace seep::service {
namespace {

void ContactsToProto(const core::DemContactState& s, v1::DemContactState* c) {
  c->set_needs_rebuild(s.needs_rebuild);
  c->set_bond_normal_stiffness(s.bond_normal_stiffness);
  c->set_bond_shear_stiffness(s.bond_shear_stiffness);
  c->set_bond_radius_multiplier(s.bond_radius_multiplier);
  c->set_bond_tensile_strength(s.bond_tensile_strength);
  c->set_bond_shear_strength(s.bond_shear_strength);
  c->mutable_pair_i()->Assign(s.pair_i.begin(), s.pair_i.end());
  c->mutable_pair_j()->Assign(s.pair_j.begin(), s.pair_j.end());
  c->mutable_pair_bond()->Assign(s.pair_bond.begin(), s.pair_bond.end());
  c->mutable_pair_damping()->Assign(s.pair_damping.begin(), s.pair_damping.end());
  c->mutable_pair_shear()->Assign(s.pair_shear.begin(), s.pair_shear.end());
  c->mutable_pair_fn()->Assign(s.pair_fn.begin(), s.pair_fn.end());
  c->mutable_pair_gap()->Assign(s.pair_gap.begin(), s.pair_gap.end());
  c->mutable_bond_i()->Assign(s.bond_i.begin(), s.bond_i.end());
  c->mutable_bond_j()->Assign(s.bond_j.begin(), s.bond_j.end());
  c->mutable_bond_half_width()->Assign(s.bond_half_width.begin(), s.bond_half_width.end());
  c->mutable_bond_fn()->Assign(s.bond_fn.begin(), s.bond_fn.end());
  c->mutable_bond_fs()->Assign(s.bond_fs.begin(), s.bond_fs.end());
  c->mutable_bond_moment()->Assign(s.bond_moment.begin(), s.bond_moment.end());
  c->mutable_wall_contact_particle()->Assign(s.wall_contact_particle.begin(),
                                             s.wall_contact_particle.end());
  c->mutable_wall_contact_wall()->Assign(s.wall_contact_wall.begin(), s.wall_contact_wall.end());
  c->mutable_wall_contact_shear()->Assign(s.wall_contact_shear.begin(), s.wall_contact_shear.end());
  c->mutable_wall_contact_fn()->Assign(s.wall_contact_fn.begin(), s.wall_contact_fn.end());
  c->mutable_wall_contact_gap()->Assign(s.wall_contact_gap.begin(), s.wall_contact_gap.end());
  c->mutable_wall_load_normal_force()->Assign(s.wall_load_normal_force.begin(),
                                              s.wall_load_normal_force.end());
  c->mutable_wall_load_stiffness_sum()->Assign(s.wall_load_stiffness_sum.begin(),
                                               s.wall_load_stiffness_sum.end());
  c->mutable_wall_load_damping_sum()->Assign(s.wall_load_damping_sum.begin(),
                                             s.wall_load_damping_sum.end());
  c->mutable_wall_load_contact_count()->Assign(s.wall_load_contact_count.begin(),
                                               s.wall_load_contact_count.end());
  c->mutable_ref_x()->Assign(s.ref_x.begin(), s.ref_x.end());
  c->mutable_ref_y()->Assign(s.ref_y.begin(), s.ref_y.end());
  c->mutable_ref_wall_x()->Assign(s.ref_wall_x.begin(), s.ref_wall_x.end());
  c->mutable_ref_wall_y()->Assign(s.ref_wall_y.begin(), s.ref_wall_y.end());
  c->set_bond_failure(std::string(s.bond_failure.begin(), s.bond_failure.end()));
  c->set_bond_reported(std::string(s.bond_reported.begin(), s.bond_reported.end()));
}

core::DemContactState ContactsFromProto(const v1::DemContactState& p) {
  core::DemContactState c;
  c.needs_rebuild = p.needs_rebuild();
  c.bond_normal_stiffness = p.bond_normal_stiffness();
  c.bond_shear_stiffness = p.bond_shear_stiffness();
  c.bond_radius_multiplier = p.bond_radius_multiplier();
  c.bond_tensile_strength = p.bond_tensile_strength();
  c.bond_shear_strength = p.bond_shear_strength();
  c.pair_i.assign(p.pair_i().begin(), p.pair_i().end());
  c.pair_j.assign(p.pair_j().begin(), p.pair_j().end());
  c.pair_bond.assign(p.pair_bond().begin(), p.pair_bond().end());
  c.pair_damping.assign(p.pair_damping().begin(), p.pair_damping().end());
  c.pair_shear.assign(p.pair_shear().begin(), p.pair_shear().end());
  c.pair_fn.assign(p.pair_fn().begin(), p.pair_fn().end());
  c.pair_gap.assign(p.pair_gap().begin(), p.pair_gap().end());
  c.bond_i.assign(p.bond_i().begin(), p.bond_i().end());
  c.bond_j.assign(p.bond_j().begin(), p.bond_j().end());
  c.bond_half_width.assign(p.bond_half_width().begin(), p.bond_half_width().end());
  c.bond_fn.assign(p.bond_fn().begin(), p.bond_fn().end());
  c.bond_fs.assign(p.bond_fs().begin(), p.bond_fs().end());
  c.bond_moment.assign(p.bond_moment().begin(), p.bond_moment().end());
  c.wall_contact_particle.assign(p.wall_contact_particle().begin(),
                                 p.wall_contact_particle().end());
  c.wall_contact_wall.assign(p.wall_contact_wall().begin(), p.wall_contact_wall().end());
  c.wall_contact_shear.assign(p.wall_contact_shear().begin(), p.wall_contact_shear().end());
  c.wall_contact_fn.assign(p.wall_contact_fn().begin(), p.wall_contact_fn().end());
  c.wall_contact_gap.assign(p.wall_contact_gap().begin(), p.wall_contact_gap().end());
  c.wall_load_normal_force.assign(p.wall_load_normal_force().begin(),
                                  p.wall_load_normal_force().end());
  c.wall_load_stiffness_sum.assign(p.wall_load_stiffness_sum().begin(),
                                   p.wall_load_stiffness_sum().end());
  c.wall_load_damping_sum.assign(p.wall_load_damping_sum().begin(),
                                 p.wall_load_damping_sum().end());
  c.wall_load_contact_count.assign(p.wall_load_contact_count().begin(),
                                   p.wall_load_contact_count().end());
  c.ref_x.assign(p.ref_x().begin(), p.ref_x().end());
  c.ref_y.assign(p.ref_y().begin(), p.ref_y().end());
  c.ref_wall_x.assign(p.ref_wall_x().begin(), p.ref_wall_x().end());
  c.ref_wall_y.assign(p.ref_wall_y().begin(), p.ref_wall_y().end());
  c.bond_failure.assign(p.bond_failure().begin(), p.bond_failure().end());
  c.bond_reported.assign(p.bond_reported().begin(), p.bond_reported().end());
  return c;
}

// Each effect's own part (core/effects/effect_state.h), one block per effect.
void EffectStatesToProto(const core::EffectStates& e, v1::MechanicsState* out) {
  out->set_bonds_broken(e.contacts.bonds_broken);
  const core::ContactsEffectState& c = e.contacts;
  for (const double v : {static_cast<double>(c.broken_traced), c.broken_x, c.broken_y, c.broken_xx,
                         c.broken_xy, c.broken_yy}) {
    out->add_broken_bond_moments(v);
  }
  out->set_max_flow_sub_steps(e.flow.max_sub_steps);
  out->set_flow_dt_crit_s(e.flow.dt_crit_s);
  out->set_flow_limiting_domain(e.flow.limiting_domain);
  out->set_breakthrough_time_s(e.redetection.breakthrough_time_s);
  out->set_redetections(e.redetection.redetections);
  out->set_peak_well_pressure_pa(e.injection.peak_well_pressure_pa);
  out->set_peak_well_time_s(e.injection.peak_well_time_s);
}

core::EffectStates EffectStatesFromProto(const v1::MechanicsState& state) {
  core::EffectStates e;
  e.contacts.bonds_broken = state.bonds_broken();
  // Absent in checkpoints written before the moments were kept: the trace then counts from zero.
  if (state.broken_bond_moments_size() == 6) {
    const auto& v = state.broken_bond_moments();
    core::ContactsEffectState& c = e.contacts;
    c.broken_traced = static_cast<std::uint64_t>(v[0]);
    c.broken_x = v[1];
    c.broken_y = v[2];
    c.broken_xx = v[3];
    c.broken_xy = v[4];
    c.broken_yy = v[5];
  }
  e.flow.max_sub_steps = state.max_flow_sub_steps();
  e.flow.dt_crit_s = state.flow_dt_crit_s();
  e.flow.limiting_domain = state.flow_limiting_domain();
  e.redetection.breakthrough_time_s = state.breakthrough_time_s();
  e.redetection.redetections = state.redetections();
  e.injection.peak_well_pressure_pa = state.peak_well_pressure_pa();
  e.injection.peak_well_time_s = state.peak_well_time_s();
  return e;
}

}  // namespace

void MechanicsStateToProto(const core::MechanicsSnapshot& snapshot, v1::MechanicsState* out) {
  out->Clear();
  out->set_dem_dt_s(snapshot.dt);
  out->set_clock_step(snapshot.clock_step);
  out->set_clock_time_s(snapshot.clock_time_s);
  out->set_fluid_limited_dt_s(snapshot.fluid_limited_dt);
  out->set_flow_every_steps(snapshot.flow_every);
  out->mutable_x()->Assign(snapshot.x.begin(), snapshot.x.end());
  out->mutable_y()->Assign(snapshot.y.begin(), snapshot.y.end());
  out->mutable_vx()->Assign(snapshot.vx.begin(), snapshot.vx.end());
  out->mutable_vy()->Assign(snapshot.vy.begin(), snapshot.vy.end());
  out->mutable_omega()->Assign(snapshot.omega.begin(), snapshot.omega.end());
  out->mutable_fx()->Assign(snapshot.fx.begin(), snapshot.fx.end());
  out->mutable_fy()->Assign(snapshot.fy.begin(), snapshot.fy.end());
  out->mutable_torque()->Assign(snapshot.torque.begin(), snapshot.torque.end());
  out->mutable_walls()->Assign(snapshot.walls.begin(), snapshot.walls.end());
  out->mutable_detection_x()->Assign(snapshot.detection_x.begin(), snapshot.detection_x.end());
  out->mutable_detection_y()->Assign(snapshot.detection_y.begin(), snapshot.detection_y.end());
  out->mutable_detection_i()->Assign(snapshot.detection_i.begin(), snapshot.detection_i.end());
  out->mutable_detection_j()->Assign(snapshot.detection_j.begin(), snapshot.detection_j.end());
  out->mutable_detection_gap()->Assign(snapshot.detection_gap.begin(),
                                       snapshot.detection_gap.end());
  out->mutable_detection_walls()->Assign(snapshot.detection_walls.begin(),
                                         snapshot.detection_walls.end());
  out->mutable_detection_wall_particle()->Assign(snapshot.detection_wall_particle.begin(),
                                                 snapshot.detection_wall_particle.end());
  out->mutable_detection_wall_wall()->Assign(snapshot.detection_wall_wall.begin(),
                                             snapshot.detection_wall_wall.end());
  out->mutable_detection_wall_gap()->Assign(snapshot.detection_wall_gap.begin(),
                                            snapshot.detection_wall_gap.end());
  out->mutable_apparent_volume()->Assign(snapshot.apparent_volume.begin(),
                                         snapshot.apparent_volume.end());
  out->mutable_pore_volume()->Assign(snapshot.pore_volume.begin(), snapshot.pore_volume.end());
  out->mutable_aperture()->Assign(snapshot.aperture.begin(), snapshot.aperture.end());
  out->mutable_pipe_head_offset()->Assign(snapshot.pipe_head_offset.begin(),
                                          snapshot.pipe_head_offset.end());
  out->set_topology_version(snapshot.topology_version);
  EffectStatesToProto(snapshot.effects, out);
  if (const auto& g = snapshot.energy_guard) {
    for (const double v : {g->initial_j, g->gravity_moment_j, g->work_j, g->fluid_work_j}) {
      out->add_energy_guard(v);
    }
    out->mutable_energy_guard_wall_load()->Assign(g->wall_load.begin(), g->wall_load.end());
    out->mutable_energy_guard_held_fx()->Assign(g->held_fx.begin(), g->held_fx.end());
    out->mutable_energy_guard_held_fy()->Assign(g->held_fy.begin(), g->held_fy.end());
    out->mutable_energy_guard_fluid_fx()->Assign(g->fluid_fx.begin(), g->fluid_fx.end());
    out->mutable_energy_guard_fluid_fy()->Assign(g->fluid_fy.begin(), g->fluid_fy.end());
  }
  if (const auto& r = snapshot.reversal_guard) {
    v1::ReversalGuardState* g = out->mutable_reversal_guard();
    g->set_disk_checks(r->disk_checks);
    g->mutable_wall_speed()->Assign(r->wall_speed.begin(), r->wall_speed.end());
    g->mutable_wall_reversals()->Assign(r->wall_reversals.begin(), r->wall_reversals.end());
  }
  ContactsToProto(snapshot.contacts, out->mutable_contacts());
}

core::MechanicsSnapshot MechanicsStateFromProto(const v1::MechanicsState& state) {
  core::MechanicsSnapshot snap;
  snap.dt = state.dem_dt_s();
  snap.clock_step = state.clock_step();
  snap.clock_time_s = state.clock_time_s();
  snap.fluid_limited_dt = state.fluid_limited_dt_s();
  snap.flow_every = state.flow_every_steps();
  snap.x.assign(state.x().begin(), state.x().end());
  snap.y.assign(state.y().begin(), state.y().end());
  snap.vx.assign(state.vx().begin(), state.vx().end());
  snap.vy.assign(state.vy().begin(), state.vy().end());
  snap.omega.assign(state.omega().begin(), state.omega().end());
  snap.fx.assign(state.fx().begin(), state.fx().end());
  snap.fy.assign(state.fy().begin(), state.fy().end());
  snap.torque.assign(state.torque().begin(), state.torque().end());
  snap.walls.assign(state.walls().begin(), state.walls().end());
  snap.detection_x.assign(state.detection_x().begin(), state.detection_x().end());
  snap.detection_y.assign(state.detection_y().begin(), state.detection_y().end());
  snap.detection_i.assign(state.detection_i().begin(), state.detection_i().end());
  snap.detection_j.assign(state.detection_j().begin(), state.detection_j().end());
  snap.detection_gap.assign(state.detection_gap().begin(), state.detection_gap().end());
  snap.detection_walls.assign(state.detection_walls().begin(), state.detection_walls().end());
  snap.detection_wall_particle.assign(state.detection_wall_particle().begin(),
                                      state.detection_wall_particle().end());
  snap.detection_wall_wall.assign(state.detection_wall_wall().begin(),
                                  state.detection_wall_wall().end());
  snap.detection_wall_gap.assign(state.detection_wall_gap().begin(),
                                 state.detection_wall_gap().end());
  snap.apparent_volume.assign(state.apparent_volume().begin(), state.apparent_volume().end());
  snap.pore_volume.assign(state.pore_volume().begin(), state.pore_volume().end());
  snap.aperture.assign(state.aperture().begin(), state.aperture().end());
  snap.pipe_head_offset.assign(state.pipe_head_offset().begin(), state.pipe_head_offset().end());
  snap.topology_version = state.topology_version();
  snap.effects = EffectStatesFromProto(state);
  // Any other length (an older checkpoint's none) leaves it unset: the guard restarts.
  if (const auto& g = state.energy_guard(); g.size() == 4) {
    core::EnergyGuardState guard;
    guard.initial_j = g[0];
    guard.gravity_moment_j = g[1];
    guard.work_j = g[2];
    guard.fluid_work_j = g[3];
    guard.wall_load.assign(state.energy_guard_wall_load().begin(),
                           state.energy_guard_wall_load().end());
    guard.held_fx.assign(state.energy_guard_held_fx().begin(), state.energy_guard_held_fx().end());
    guard.held_fy.assign(state.energy_guard_held_fy().begin(), state.energy_guard_held_fy().end());
    guard.fluid_fx.assign(state.energy_guard_fluid_fx().begin(),
                          state.energy_guard_fluid_fx().end());
    guard.fluid_fy.assign(state.energy_guard_fluid_fy().begin(),
                          state.energy_guard_fluid_fy().end());
    snap.energy_guard = std::move(guard);
  }
  if (state.has_reversal_guard()) {
    const v1::ReversalGuardState& g = state.reversal_guard();
    core::ReversalGuardState guard;
    guard.disk_checks = g.disk_checks();
    guard.wall_speed.assign(g.wall_speed().begin(), g.wall_speed().end());
    guard.wall_reversals.assign(g.wall_reversals().begin(), g.wall_reversals().end());
    snap.reversal_guard = std::move(guard);
  }
  snap.contacts = ContactsFromProto(state.contacts());
  return snap;
}

}  // namespace seep::service
