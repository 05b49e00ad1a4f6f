// The mechanical effects: contacts (which also fixes the DEM step), bonds, gravity, local
// damping and walls (fixed or servo-controlled).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>

#include "effect_factories.h"
#include "seep/core/dem/dem_integrator.h"
#include "seep/core/dem/servo_wall.h"
#include "seep/core/effects/effect_set.h"
#include "seep/core/network/scene_walls.h"

namespace seep::core::effects_internal {
namespace {

class ContactsEffect final : public EffectWithSpec<ContactsEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  std::uint32_t Hooks() const override { return kForceHook; }

  Status Bind(LiveState& s, const EffectSet&) override {
    const Packing& packing = s.net.packing;
    SEEP_ASSIGN_OR_RETURN(s.particles, MakeDemParticles(packing, spec_.density_kg_m3));
    double radius_sum = 0.0;
    for (double r : packing.radius) radius_sum += r;
    const double mean_radius = radius_sum / static_cast<double>(packing.size());
    DemContactSettings settings;
    settings.law = spec_.law;
    settings.skin = spec_.skin_m > 0.0 ? spec_.skin_m : 0.1 * mean_radius;
    // The flow contacts (re-detection) are read from the neighbour list, so it must hold every
    // pair that can come within the contact gap before the next rebuild.
    settings.flow_gap = SceneContactGap(*s.scene, mean_radius);
    SEEP_ASSIGN_OR_RETURN(DemContactForces forces, DemContactForces::Create(settings));
    s.contacts.emplace(std::move(forces));
    return Status::Ok();
  }

  // The first force of a step: sets (not adds) the contact and bond forces.
  Status AddForces(LiveState& s, const StepInfo& info) override {
    SEEP_RETURN_IF_ERROR(s.contacts->SetForces(&s.particles, s.walls, info.dt, &s.counters.dem));
    const DemParticles& p = s.particles;
    for (const BondBreak& b : s.contacts->broken_bonds()) {
      const auto i = static_cast<std::size_t>(b.i), j = static_cast<std::size_t>(b.j);
      const double x = 0.5 * (p.x[i] + p.x[j]), y = 0.5 * (p.y[i] + p.y[j]);
      state_.broken_x += x;
      state_.broken_y += y;
      state_.broken_xx += x * x;
      state_.broken_xy += x * y;
      state_.broken_yy += y * y;
      ++state_.broken_traced;
    }
    state_.bonds_broken += s.contacts->broken_bonds().size();
    return Status::Ok();
  }

  void SaveTo(EffectStates* out) const override { out->contacts = state_; }
  void RestoreFrom(const EffectStates& in) override { state_ = in.contacts; }

 private:
  // The fracture's trace: the principal axis of the broken bonds' midpoints (where they broke),
  // fracture_angle_deg in [0, 180) from +x towards +y, and fracture_spread_ratio, the minor over
  // the major variance (0: the breaks lie on a line, 1: no direction), once two bonds broke.
  void AddFractureTrace(Metrics* m) const {
    if (state_.broken_traced < 2) return;
    const double n = static_cast<double>(state_.broken_traced);
    const double mx = state_.broken_x / n, my = state_.broken_y / n;
    const double cxx = state_.broken_xx / n - mx * mx;
    const double cyy = state_.broken_yy / n - my * my;
    const double cxy = state_.broken_xy / n - mx * my;
    double angle = 0.5 * std::atan2(2.0 * cxy, cxx - cyy) * 180.0 / std::numbers::pi;
    if (angle < 0.0) angle += 180.0;
    const double mean = 0.5 * (cxx + cyy);
    const double radius = std::hypot(0.5 * (cxx - cyy), cxy);
    (*m)["fracture_angle_deg"] = angle;
    (*m)["fracture_spread_ratio"] = mean + radius > 0.0 ? (mean - radius) / (mean + radius) : 1.0;
  }

 public:
  void AddMetrics(const LiveState& s, Metrics* m) const override {
    (*m)["bonds_broken"] = static_cast<double>(state_.bonds_broken);
    AddFractureTrace(m);
    (*m)["particle_count"] = static_cast<double>(s.particles.size());
    (*m)["kinetic_energy_j_per_m"] = KineticEnergy(s.particles);
  }
  void AddSeriesColumns(const LiveState&, std::vector<std::string>* columns) const override {
    columns->push_back("bonds_broken");
  }
  void AddSample(const LiveState&, std::vector<double>* row) const override {
    row->push_back(static_cast<double>(state_.bonds_broken));
  }

 private:
  ContactsEffectState state_;
};

class BondsEffect final : public EffectWithSpec<BondsEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  std::uint32_t Hooks() const override { return 0; }  // evaluated inside the contact pass

  Status Bind(LiveState& s, const EffectSet&) override {
    SEEP_ASSIGN_OR_RETURN(const std::size_t bonds,
                          s.contacts->BondTouchingPairs(&s.particles, spec_.params,
                                                        spec_.tolerance_m, &s.counters.dem));
    if (bonds == 0) {
      return FailedPrecondition(fmt::format(
          "scene.effects.bonds: no pair of particles lies within tolerance_m = {} m; nothing "
          "to bond",
          spec_.tolerance_m));
    }
    return Status::Ok();
  }
};

class GravityEffect final : public EffectWithSpec<GravityEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  std::uint32_t Hooks() const override { return kForceHook; }
  Status AddForces(LiveState& s, const StepInfo&) override {
    // A frozen packing: gravity weighs the fluid alone (the flow effect's head offsets).
    if (!s.moves()) return Status::Ok();
    AddGravity(&s.particles, spec_.gx_m_s2, spec_.gy_m_s2, &s.counters.dem);
    return Status::Ok();
  }
};

class LocalDampingEffect final : public EffectWithSpec<LocalDampingEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  std::uint32_t Hooks() const override { return kPostForceHook; }
  Status PostForce(LiveState& s, const StepInfo& info) override {
    ApplyLocalDamping(&s.particles, spec_.alpha, info.dt, &s.counters.dem);
    return Status::Ok();
  }
  // A stage may change alpha (e.g. damped confinement, then undamped injection).
  Status Reconfigure(LiveState& s) override {
    spec_.alpha = FindEffect<LocalDampingEffectSpec>(*s.scene)->alpha;
    return Status::Ok();
  }
};

class WallsEffect final : public EffectWithSpec<WallsEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  std::uint32_t Hooks() const override { return kPostForceHook; }

  // Each side wall touches the outermost disk surface of its side of the packing's bounding box;
  // a segment wall is where its end points say, and the contacts learn its extent.
  Status Bind(LiveState& s, const EffectSet&) override {
    const DemParticles& p = s.particles;
    SEEP_ASSIGN_OR_RETURN(const std::vector<PlacedWall> placed,
                          PlaceWalls(spec_, p.x, p.y, p.radius));
    s.walls.clear();
    servo_.clear();
    std::vector<DemWallExtent> extents;
    for (std::size_t w = 0; w < placed.size(); ++w) {
      s.walls.push_back(placed[w].wall);
      extents.push_back(placed[w].extent);
      ServoWallSettings servo;
      servo.target_stress = spec_.walls[w].servo_stress_pa;
      servo.length = placed[w].length;
      servo.gain_fraction = spec_.walls[w].servo_gain_fraction;
      servo.max_speed = spec_.walls[w].servo_max_speed_m_s;
      servo.first_contact_stiffness = FindEffect<ContactsEffectSpec>(*s.scene)->law.kn;
      servo_.push_back(servo);
    }
    placed_ = s.walls;
    SEEP_RETURN_IF_ERROR(s.contacts->SetWallExtents(std::move(extents)));
    SetPrescribedVelocities(s);
    s.wall_stress_pa.assign(s.walls.size(), 0.0);
    s.wall_effective_stress_pa.assign(s.walls.size(), 0.0);
    return Status::Ok();
  }

  // A stage switched a wall between fixed, servo and velocity control or moved its target. A
  // servo keeps the velocity it has (its own state, in the checkpoint); a velocity-controlled
  // wall takes its speed; a fixed one stops.
  Status Reconfigure(LiveState& s) override {
    const std::vector<WallSpec>& live = FindEffect<WallsEffectSpec>(*s.scene)->walls;
    for (std::size_t w = 0; w < s.walls.size(); ++w) {
      servo_[w].target_stress = live[w].servo_stress_pa;
      if (live[w].servo_stress_pa > 0.0) continue;
      const double v = live[w].normal_velocity_m_s.value_or(0.0);
      s.walls[w].vx = v * s.walls[w].nx;
      s.walls[w].vy = v * s.walls[w].ny;
    }
    return Status::Ok();
  }

  // The servo holds the total stress (contacts + the pore pressure of the domains the wall
  // closes, with their fluid stiffness in its gain) unless the wall asks for the effective one.
  Status PostForce(LiveState& s, const StepInfo& info) override {
    const std::vector<DemWallLoad>& loads = s.contacts->wall_loads();
    for (std::size_t w = 0; w < s.walls.size(); ++w) {
      DemWallLoad load = loads[w];
      const double pore = w < s.wall_pore_force.size() ? s.wall_pore_force[w] : 0.0;
      s.wall_effective_stress_pa[w] = load.normal_force / servo_[w].length;
      s.wall_stress_pa[w] = (load.normal_force + pore) / servo_[w].length;
      if (servo_[w].target_stress > 0.0) {
        if (!spec_.walls[w].servo_effective_stress) {
          load.normal_force += pore;
          if (w < s.wall_fluid_stiffness.size()) load.stiffness_sum += s.wall_fluid_stiffness[w];
        }
        ApplyServo(servo_[w], load, info.dt, &s.walls[w], &s.counters.dem);
      }
    }
    return Status::Ok();
  }

  // Per wall, the position along its normal and the measured normal stresses at the last step:
  // total (contacts + pore pressure) and effective (contacts alone).
  void AddMetrics(const LiveState& s, Metrics* m) const override {
    for (std::size_t w = 0; w < spec_.walls.size(); ++w) {
      const std::string name = WallName(spec_.walls[w], w);
      (*m)[fmt::format("{}_wall_position_m", name)] = Position(s, w);
      (*m)[fmt::format("{}_wall_stress_pa", name)] = s.wall_stress_pa[w];
      (*m)[fmt::format("{}_wall_effective_stress_pa", name)] = s.wall_effective_stress_pa[w];
    }
  }
  void AddSeriesColumns(const LiveState&, std::vector<std::string>* columns) const override {
    for (const char* column : {"position_m", "stress_pa", "effective_stress_pa"}) {
      for (std::size_t w = 0; w < spec_.walls.size(); ++w) {
        columns->push_back(fmt::format("{}_wall_{}", WallName(spec_.walls[w], w), column));
      }
    }
  }
  void AddSample(const LiveState& s, std::vector<double>* row) const override {
    for (std::size_t w = 0; w < spec_.walls.size(); ++w) row->push_back(Position(s, w));
    row->insert(row->end(), s.wall_stress_pa.begin(), s.wall_stress_pa.end());
    row->insert(row->end(), s.wall_effective_stress_pa.begin(), s.wall_effective_stress_pa.end());
  }

 private:
  // A velocity-controlled wall moves at its speed along its normal from the start (MoveWalls
  // advances it; the velocity is in the checkpointed wall state).
  void SetPrescribedVelocities(LiveState& s) const {
    for (std::size_t w = 0; w < s.walls.size(); ++w) {
      if (const auto& v = spec_.walls[w].normal_velocity_m_s) {
        s.walls[w].vx = *v * s.walls[w].nx;
        s.walls[w].vy = *v * s.walls[w].ny;
      }
    }
  }

  // A side wall: its x (left, right) or y (bottom, top). A segment wall: how far it has moved
  // along its normal since it was placed.
  double Position(const LiveState& s, std::size_t w) const {
    const DemWall& wall = s.walls[w];
    if (spec_.walls[w].segment) {
      return (wall.px - placed_[w].px) * wall.nx + (wall.py - placed_[w].py) * wall.ny;
    }
    const WallSide side = spec_.walls[w].side;
    const bool vertical = side == WallSide::kLeft || side == WallSide::kRight;
    return vertical ? wall.px : wall.py;
  }

  std::vector<ServoWallSettings> servo_;
  std::vector<DemWall> placed_;  // the walls where Bind placed them
};

}  // namespace

std::unique_ptr<Effect> MakeContactsEffect(const ContactsEffectSpec& spec) {
  return std::make_unique<ContactsEffect>(spec);
}
std::unique_ptr<Effect> MakeBondsEffect(const BondsEffectSpec& spec) {
  return std::make_unique<BondsEffect>(spec);
}
std::unique_ptr<Effect> MakeGravityEffect(const GravityEffectSpec& spec) {
  return std::make_unique<GravityEffect>(spec);
}
std::unique_ptr<Effect> MakeLocalDampingEffect(const LocalDampingEffectSpec& spec) {
  return std::make_unique<LocalDampingEffect>(spec);
}
std::unique_ptr<Effect> MakeWallsEffect(const WallsEffectSpec& spec) {
  return std::make_unique<WallsEffect>(spec);
}

}  // namespace seep::core::effects_internal
