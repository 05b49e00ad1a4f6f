// Stepper::TakeSnapshot / Restore: the live state the stepper owns, and each effect's own part.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <optional>
#include <string_view>

#include "seep/core/effects/flow_effect.h"
#include "seep/core/run/stepper.h"

namespace seep::core {
namespace {

Status CheckLength(const char* field, std::size_t got, std::size_t want) {
  if (got == want) return Status::Ok();
  return DataLoss(
      fmt::format("snapshot.mechanics.{}: {} values, this scene needs {}", field, got, want));
}

// `field` is the path below "snapshot." (e.g. "pressure", "mechanics.x").
Status CheckFinite(std::string_view field, const std::vector<double>& v) {
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (!std::isfinite(v[i])) {
      return DataLoss(fmt::format("snapshot.{}[{}]: not finite", field, i));
    }
  }
  return Status::Ok();
}

Status CheckPressures(const std::vector<double>& pressure, std::size_t nodes) {
  if (pressure.size() != nodes) {
    return DataLoss(fmt::format(
        "snapshot.pressure: {} values for a network of {} nodes (not this scene's state)",
        pressure.size(), nodes));
  }
  return CheckFinite("pressure", pressure);
}

// The books: finite totals, one per boundary of this scene (or none kept: a checkpoint written
// before the books existed).
Status CheckLedger(const std::optional<FluidLedger>& saved, std::size_t boundaries) {
  if (!saved) return Status::Ok();
  const FluidLedger& ledger = *saved;
  if (ledger.left_m2.size() != boundaries) {
    return DataLoss(fmt::format("snapshot.ledger.left_m2: {} boundaries, this scene has {}",
                                ledger.left_m2.size(), boundaries));
  }
  SEEP_RETURN_IF_ERROR(CheckFinite("ledger.left_m2", ledger.left_m2));
  return CheckFinite("ledger", {ledger.injected_m2, ledger.compressed_m2, ledger.pore_growth_m2,
                                ledger.redetection_m2, ledger.handled_m2});
}

// Takes the snapshot's books; a snapshot without them (none kept yet) starts the books at its
// step, so the balance the run reports covers what it saw.
void RestoreLedger(const std::optional<FluidLedger>& saved, std::uint64_t step,
                   FluidLedger* ledger) {
  if (saved) {
    *ledger = *saved;
    return;
  }
  const std::size_t boundaries = ledger->left_m2.size();
  *ledger = FluidLedger{};
  ledger->left_m2.assign(boundaries, 0.0);
  ledger->since_step = step;
}

// The contact pairs a network was detected from: sorted pairs of this scene's particles.
Status CheckDetectionPairs(const MechanicsSnapshot& snap, std::size_t particles) {
  const std::size_t contacts = snap.detection_i.size();
  SEEP_RETURN_IF_ERROR(CheckLength("detection_j", snap.detection_j.size(), contacts));
  SEEP_RETURN_IF_ERROR(CheckLength("detection_gap", snap.detection_gap.size(), contacts));
  for (std::size_t c = 0; c < contacts; ++c) {
    const std::int32_t i = snap.detection_i[c], j = snap.detection_j[c];
    const bool sorted = c == 0 || snap.detection_i[c - 1] < i ||
                        (snap.detection_i[c - 1] == i && snap.detection_j[c - 1] < j);
    if (i < 0 || j <= i || static_cast<std::size_t>(j) >= particles || !sorted) {
      return DataLoss(
          fmt::format("snapshot.mechanics.detection_i/j[{}]: ({}, {}) is not a sorted "
                      "pair of particles of this scene",
                      c, i, j));
    }
  }
  return Status::Ok();
}

// The particles' dynamic fields, as the snapshot and the DEM arrays hold them (mass, radius and
// inertia come from the scene).
struct ParticleField {
  const char* name;
  std::vector<double> MechanicsSnapshot::*snapshot;
  std::vector<double> DemParticles::*particles;
};
constexpr ParticleField kParticleFields[] = {
    {"x", &MechanicsSnapshot::x, &DemParticles::x},
    {"y", &MechanicsSnapshot::y, &DemParticles::y},
    {"vx", &MechanicsSnapshot::vx, &DemParticles::vx},
    {"vy", &MechanicsSnapshot::vy, &DemParticles::vy},
    {"omega", &MechanicsSnapshot::omega, &DemParticles::omega},
    {"fx", &MechanicsSnapshot::fx, &DemParticles::fx},
    {"fy", &MechanicsSnapshot::fy, &DemParticles::fy},
    {"torque", &MechanicsSnapshot::torque, &DemParticles::torque}};

}  // namespace

SimulationSnapshot Stepper::TakeSnapshot() const {
  SimulationSnapshot snap;
  snap.step = step_;
  snap.time_s = time_s_;
  const auto pressure = state_.net.flow.pressure();
  snap.pressure.assign(pressure.begin(), pressure.end());
  snap.step_mass_balance_error = state_.books.step_error;
  snap.worst_mass_balance_error = state_.books.worst_error;
  snap.ledger = state_.books.ledger;
  snap.series = series_;
  if (state_.moves()) SaveMechanics(&snap.mechanics.emplace());
  if (program_.active()) snap.stages = program_.state();
  return snap;
}

void Stepper::SaveMechanics(MechanicsSnapshot* out) const {
  const LiveState& s = state_;
  const DemParticles& p = s.particles;
  for (const ParticleField& f : kParticleFields) out->*f.snapshot = p.*f.particles;
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
  for (const WallLine& w : s.net.walls) {
    out->detection_walls.insert(out->detection_walls.end(), {w.px, w.py, w.nx, w.ny});
  }
  out->detection_wall_particle = s.net.wall_contacts.particle;
  out->detection_wall_wall = s.net.wall_contacts.wall;
  out->detection_wall_gap = s.net.wall_contacts.gap;
  if (s.has_network) {
    const auto apparent = s.net.flow.apparent_volume();
    const auto aperture = s.net.flow.pipe_aperture();
    out->apparent_volume.assign(apparent.begin(), apparent.end());
    out->pore_volume = ReportedPoreVolumes();
    out->aperture.assign(aperture.begin(), aperture.end());
    const auto offset = s.net.flow.pipe_head_offset();
    out->pipe_head_offset.assign(offset.begin(), offset.end());
  }
  out->topology_version = s.topology_version;
  out->dt = dt_;
  out->clock_step = clock_step_;
  out->clock_time_s = clock_time_s_;
  out->fluid_limited_dt = fluid_limited_dt_;
  out->flow_every = flow_every_;
  for (const auto& effect : effects_.all) effect->SaveTo(&out->effects);
  guard_.SaveTo(&out->energy_guard.emplace());
  reversals_.SaveTo(&out->reversal_guard.emplace());
}

Status Stepper::Restore(const SimulationSnapshot& snap) {
  if (state_.moves() && !snap.mechanics) {
    return DataLoss("snapshot.mechanics: missing; this scene's particles move");
  }
  if (!state_.moves() && snap.mechanics) {
    return DataLoss("snapshot.mechanics: present, but this scene's particles do not move");
  }
  if (program_.active() != snap.stages.has_value()) {
    return DataLoss(program_.active() ? "snapshot.stages: missing; this scene has stages"
                                      : "snapshot.stages: present, but this scene has no stages");
  }
  std::uint64_t total_steps = total_steps_;
  if (snap.mechanics && snap.mechanics->dt != 0.0) {
    SEEP_ASSIGN_OR_RETURN(total_steps, ClockTotalSteps(*snap.mechanics, snap.step));
  }
  // A staged run has no last step known in advance (its stages end on conditions).
  if (!program_.active() && snap.step > total_steps) {
    return DataLoss(
        fmt::format("snapshot.step: {} is past this scene's last step {}", snap.step, total_steps));
  }
  // The stages first: the settings of the moment resumed at are the live scene's before the
  // network is rebuilt from it and the effects re-bind (the injection rate, boundary pressures).
  StageProgram program = program_;
  StageControls controls = applied_;
  if (snap.stages) {
    SEEP_RETURN_IF_ERROR(program.Restore(*snap.stages, snap.step, snap.time_s));
    controls = program.ControlsAt(snap.time_s - snap.stages->start_time_s);
  }
  // (A scene without stages never has its settings written: it keeps the scene's own.)
  const StageControls before = applied_;
  if (snap.stages) WriteControls(controls, &scene_);
  // On an error below the live scene goes back to what it was.
  const auto undo = [&](Status status) {
    if (snap.stages) WriteControls(before, &scene_);
    return status;
  };
  for (const auto& [field, value] :
       {std::pair{"step_mass_balance_error", snap.step_mass_balance_error},
        std::pair{"worst_mass_balance_error", snap.worst_mass_balance_error}}) {
    if (!(std::isfinite(value) && value >= 0.0)) {
      return DataLoss(fmt::format("snapshot.{}: must be finite and >= 0 (got {})", field, value));
    }
  }
  SEEP_RETURN_IF_ERROR(CheckLedger(snap.ledger, state_.books.ledger.left_m2.size()));
  if (snap.mechanics && snap.mechanics->energy_guard) {
    SEEP_RETURN_IF_ERROR(guard_.Validate(*snap.mechanics->energy_guard, state_));
  }
  if (snap.mechanics && snap.mechanics->reversal_guard) {
    SEEP_RETURN_IF_ERROR(reversals_.Validate(*snap.mechanics->reversal_guard, state_));
  }
  if (snap.series.columns != series_.columns ||
      snap.series.values.size() % series_.columns.size() != 0) {
    return DataLoss("snapshot.series: columns or row length differ from this scene's");
  }
  if (snap.mechanics) {
    if (Status status = RestoreMechanics(*snap.mechanics, snap.pressure); !status.ok()) {
      return undo(status);
    }
  } else if (Status status = CheckPressures(snap.pressure, state_.net.flow.num_domains());
             !status.ok()) {
    return undo(status);
  }
  std::copy(snap.pressure.begin(), snap.pressure.end(), state_.net.flow.mutable_pressure().begin());
  if (snap.mechanics && snap.mechanics->dt != 0.0) {
    const MechanicsSnapshot& m = *snap.mechanics;
    dt_ = m.dt;
    clock_step_ = m.clock_step;
    clock_time_s_ = m.clock_time_s;
    fluid_limited_dt_ = m.fluid_limited_dt;
    flow_every_ = m.flow_every;
    if (effects_.flow != nullptr) effects_.flow->set_every_steps(flow_every_);
    total_steps_ = total_steps;
  }
  if (snap.stages) {
    program_ = std::move(program);
    applied_ = std::move(controls);
    applied_stage_ = program_.state().index;
    total_steps_ = snap.step + std::max<std::uint64_t>(1, program_.EstimateSteps(dt_));
  }
  step_ = snap.step;
  time_s_ = snap.time_s;
  state_.books.step_error = snap.step_mass_balance_error;
  state_.books.worst_error = snap.worst_mass_balance_error;
  RestoreLedger(snap.ledger, snap.step, &state_.books.ledger);
  series_ = snap.series;
  series_stride_ = SeriesStrideAt(step_);
  const std::size_t width = series_.columns.size();
  if (const std::size_t rows = series_.rows(); rows > 0) {
    latest_sample_.assign(series_.values.end() - static_cast<std::ptrdiff_t>(width),
                          series_.values.end());
  }
  // The stage's settings of this moment, taken up again (idempotent: the same values the run
  // would apply at its next step); the fixed pressures over the snapshot's copies.
  if (program_.active()) SEEP_RETURN_IF_ERROR(ReconfigureAll());
  if (snap.mechanics) {
    guard_.RestoreFrom(snap.mechanics->energy_guard, state_);
    reversals_.RestoreFrom(snap.mechanics->reversal_guard, state_);
  }
  return Status::Ok();
}

Status Stepper::RestoreMechanics(const MechanicsSnapshot& snap,
                                 const std::vector<double>& pressure) {
  LiveState& s = state_;
  const std::size_t n = s.particles.size();
  std::vector<std::pair<const char*, const std::vector<double>*>> fields;
  for (const ParticleField& f : kParticleFields) fields.emplace_back(f.name, &(snap.*f.snapshot));
  fields.emplace_back("detection_x", &snap.detection_x);
  fields.emplace_back("detection_y", &snap.detection_y);
  for (const auto& [name, values] : fields) {
    SEEP_RETURN_IF_ERROR(CheckLength(name, values->size(), n));
    SEEP_RETURN_IF_ERROR(CheckFinite(fmt::format("mechanics.{}", name), *values));
  }
  SEEP_RETURN_IF_ERROR(CheckLength("walls", snap.walls.size(), 6 * s.walls.size()));
  SEEP_RETURN_IF_ERROR(CheckFinite("mechanics.walls", snap.walls));
  SEEP_RETURN_IF_ERROR(CheckDetectionPairs(snap, n));
  // The network of the detection, rebuilt exactly as the run built it.
  SceneNetwork net;
  if (s.has_network) {
    net.packing = s.net.packing;
    net.packing.x = snap.detection_x;
    net.packing.y = snap.detection_y;
    net.contacts.i = snap.detection_i;
    net.contacts.j = snap.detection_j;
    net.contacts.gap = snap.detection_gap;
    SEEP_RETURN_IF_ERROR(
        CheckLength("detection_walls", snap.detection_walls.size(), 4 * s.net.walls.size()));
    SEEP_RETURN_IF_ERROR(CheckFinite("mechanics.detection_walls", snap.detection_walls));
    for (std::size_t w = 0; w < s.net.walls.size(); ++w) {
      const double* v = &snap.detection_walls[4 * w];
      net.walls.push_back({v[0], v[1], v[2], v[3]});
    }
    const std::size_t wall_contacts = snap.detection_wall_particle.size();
    SEEP_RETURN_IF_ERROR(
        CheckLength("detection_wall_wall", snap.detection_wall_wall.size(), wall_contacts));
    SEEP_RETURN_IF_ERROR(
        CheckLength("detection_wall_gap", snap.detection_wall_gap.size(), wall_contacts));
    net.wall_contacts.particle = snap.detection_wall_particle;
    net.wall_contacts.wall = snap.detection_wall_wall;
    net.wall_contacts.gap = snap.detection_wall_gap;
    net.mean_radius_m = s.net.mean_radius_m;
    net.weight_origin_x_m = s.net.weight_origin_x_m;
    net.weight_origin_y_m = s.net.weight_origin_y_m;
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
    SEEP_RETURN_IF_ERROR(CheckFinite("mechanics.apparent_volume", snap.apparent_volume));
    SEEP_RETURN_IF_ERROR(CheckFinite("mechanics.pore_volume", snap.pore_volume));
    SEEP_RETURN_IF_ERROR(CheckFinite("mechanics.aperture", snap.aperture));
    if (!snap.pipe_head_offset.empty()) {
      SEEP_RETURN_IF_ERROR(
          CheckLength("pipe_head_offset", snap.pipe_head_offset.size(), net.flow.num_pipes()));
      SEEP_RETURN_IF_ERROR(CheckFinite("mechanics.pipe_head_offset", snap.pipe_head_offset));
    }
  }
  SEEP_RETURN_IF_ERROR(
      CheckPressures(pressure, s.has_network ? net.flow.num_domains() : s.net.flow.num_domains()));
  // Everything checked that can be without touching the state; the contact state checks itself
  // before it changes anything.
  SEEP_RETURN_IF_ERROR(s.contacts->RestoreState(snap.contacts, n, s.walls.size()));
  DemParticles& p = s.particles;
  for (const ParticleField& f : kParticleFields) p.*f.particles = snap.*f.snapshot;
  for (std::size_t w = 0; w < s.walls.size(); ++w) {
    const double* v = &snap.walls[6 * w];
    s.walls[w] = DemWall{v[0], v[1], v[2], v[3], v[4], v[5]};
  }
  s.detection_x = snap.detection_x;
  s.detection_y = snap.detection_y;
  s.topology_version = snap.topology_version;
  // Each effect's own part last, over what the re-bind below measured.
  const auto restore_effects = [&] {
    for (const auto& effect : effects_.all) effect->RestoreFrom(snap.effects);
  };
  if (!s.has_network) {
    restore_effects();
    return Status::Ok();
  }
  s.net = std::move(net);
  if (!std::equal(snap.aperture.begin(), snap.aperture.end(), s.net.flow.pipe_aperture().begin())) {
    SEEP_RETURN_IF_ERROR(s.net.flow.SetApertures(snap.aperture, scene_.fluid.viscosity_pa_s));
  }
  // Effects bind to the network as detected (the volume updater captures its rattler correction
  // from the detected volumes), then the volumes move on to the snapshot's.
  SEEP_RETURN_IF_ERROR(RebindAll());
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
  // The heads as the run last measured them (the rebind measured them at the restored positions).
  if (!snap.pipe_head_offset.empty()) {
    SEEP_RETURN_IF_ERROR(s.net.flow.SetPipeHeadOffsets(snap.pipe_head_offset));
  }
  restore_effects();
  return Status::Ok();
}

}  // namespace seep::core
