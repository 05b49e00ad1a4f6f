// The fluid effects no other code holds a handle to: pressure forces on the particles and
// apertures from the contacts; and the DEM step the fluid's stiffness allows.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "../parallel_threshold.h"
#include "effect_factories.h"
#include "seep/core/coupling/buoyancy.h"
#include "seep/core/coupling/contact_apertures.h"
#include "seep/core/coupling/pressure_forces.h"
#include "seep/core/effects/fluid_stable_step.h"
#include "seep/core/effects/fluid_vertices.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/log.h"
#include "seep/core/network/fluid_weight.h"

namespace seep::core::effects_internal {
namespace {

ParticleView CurrentView(const LiveState& s) {
  return ParticleView{s.particles.x, s.particles.y, s.particles.radius};
}

class FluidForcesEffect final : public Effect {
 public:
  FluidForcesEffect() : Effect(kEffectKind<FluidForcesEffectSpec>) {}
  std::uint32_t Hooks() const override { return kForceHook; }

  Status Bind(LiveState& s, const EffectSet&) override {
    weight_ = SceneFluidWeight(*s.scene);
    return Rebind(s);
  }

  // Which reservoir node (or -1: an impermeable hull contact) each boundary pipe of the domain
  // network drains into, from the flow network's pipes past the interior ones.
  Status Rebind(LiveState& s) override {
    const DomainNetwork& d = s.net.domains;
    std::vector<std::pair<std::int32_t, std::int32_t>> contact_node;
    const auto b = s.net.flow.pipe_domain_b();
    for (std::size_t p = d.num_pipes(); p < s.net.pipe_contact.size(); ++p) {
      contact_node.emplace_back(s.net.pipe_contact[p], b[p]);
    }
    std::sort(contact_node.begin(), contact_node.end());
    reservoir_of_boundary_pipe_.assign(d.num_boundary_pipes(), -1);
    for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
      const auto it = std::lower_bound(
          contact_node.begin(), contact_node.end(),
          std::make_pair(d.boundary_pipe_contact[k], std::numeric_limits<std::int32_t>::min()));
      if (it != contact_node.end() && it->first == d.boundary_pipe_contact[k]) {
        reservoir_of_boundary_pipe_[k] = it->second;
      }
    }
    boundary_pressure_.assign(d.num_boundary_pipes(), 0.0);
    const DomainWalls& walls = d.walls;
    SEEP_RETURN_IF_ERROR(kernel_.Bind(d, s.particles.size() + walls.num_vertices()));
    slot_pressure_.assign(kernel_.num_slots(), 0.0);
    vertex_fx_.assign(walls.num_vertices(), 0.0);
    vertex_fy_.assign(walls.num_vertices(), 0.0);
    // The domains each wall closes, with the length of wall they span at detection and, for a
    // drained wall, the conductance of their pipe to the platen (the network's, scene_network.cc).
    // A drained pore gives way only as fast as the platen takes its fluid: within a step it is as
    // stiff as a sealed one unless K_f C dt / V_s is not small (counting it as soft left the servo
    // of real water's drained platens 6,000 times too fast; they chattered at full speed).
    wall_pores_.clear();
    for (std::size_t k = 0; k < d.num_boundary_pipes(); ++k) {
      const std::int32_t c = d.boundary_pipe_contact[k];
      if (!walls.IsWallEdge(c) || walls.edge_particle[walls.Edge(c)] >= 0) continue;
      const std::int32_t wall = walls.edge_wall[walls.Edge(c)];
      const double length = walls.edge_gap[walls.Edge(c)];
      wall_pores_.push_back(
          {wall, d.boundary_pipe_domain[k], length,
           WallDrainConductance(*s.scene, static_cast<std::size_t>(wall), length)});
    }
    // Sized by the network's walls: the walls effect binds after this one.
    s.wall_pore_force.assign(s.net.walls.size(), 0.0);
    s.wall_fluid_stiffness.assign(s.net.walls.size(), 0.0);
    if (weight_) wetted_stretches_ = WettedWallStretches(d);
    return Status::Ok();
  }

  Status AddForces(LiveState& s, const StepInfo& info) override {
    std::span<const double> pressure = s.net.flow.pressure();
    if (weight_) {
      // The chord rule on the heads P - W, then Archimedes (coupling/buoyancy.h); the weights
      // from this step's positions, as the chords are.
      SEEP_RETURN_IF_ERROR(ComputeNodeWeightPressures(s.net, s.step_vertices.CurrentInStep(s),
                                                      *weight_, &node_weight_));
      head_.resize(pressure.size());
      for (std::size_t n = 0; n < pressure.size(); ++n) head_[n] = pressure[n] - node_weight_[n];
      pressure = head_;
      AddBuoyancy(CurrentView(s), weight_->x, weight_->y, s.particles.fx.data(),
                  s.particles.fy.data());
    }
    for (std::size_t k = 0; k < reservoir_of_boundary_pipe_.size(); ++k) {
      const std::int32_t node = reservoir_of_boundary_pipe_[k];
      boundary_pressure_[k] = node >= 0 ? pressure[static_cast<std::size_t>(node)]
                                        : std::numeric_limits<double>::quiet_NaN();
    }
    const std::size_t domains = s.net.domains.num_domains();
    const std::span<const double> domain_pressure = pressure.subspan(0, domains);
    SEEP_RETURN_IF_ERROR(
        outer_.Compute(s.net.domains, domain_pressure, boundary_pressure_, &arc_pressure_));
    std::copy(domain_pressure.begin(), domain_pressure.end(), slot_pressure_.begin());
    std::copy(arc_pressure_.begin(), arc_pressure_.end(),
              slot_pressure_.begin() + static_cast<std::ptrdiff_t>(domains));
    ++s.counters.pressure_force_passes;
    if (vertex_fx_.empty()) {
      kernel_.Apply(CurrentView(s), slot_pressure_.data(), s.particles.fx.data(),
                    s.particles.fy.data());
      return Status::Ok();
    }
    std::fill(vertex_fx_.begin(), vertex_fx_.end(), 0.0);
    std::fill(vertex_fy_.begin(), vertex_fy_.end(), 0.0);
    kernel_.Apply(s.step_vertices.CurrentInStep(s), slot_pressure_.data(),
                  {s.particles.fx.data(), s.particles.fy.data(), s.particles.size(),
                   vertex_fx_.data(), vertex_fy_.data()});
    AddWallLoads(s, info.dt);
    if (weight_) AddWallWeightLoads(s);
    return Status::Ok();
  }

 private:
  struct WallPore {
    std::int32_t wall, domain;
    double length;  // of the stretch of wall closing it, at detection
    double drain;   // the conductance of its pipe to a drained wall's platen, m^2/(Pa s); 0 sealed
  };

  // The wall vertices' forces summed per wall along its inward normal (a corner's force splits
  // between its two walls by projection, exact for walls at right angles), and the stiffness of
  // the sealed pores along each wall (dP = K_f dV / V_s, dV = l du).
  void AddWallLoads(LiveState& s, double dt) const {
    const DomainWalls& walls = s.net.domains.walls;
    std::fill(s.wall_pore_force.begin(), s.wall_pore_force.end(), 0.0);
    for (std::size_t v = 0; v < walls.num_vertices(); ++v) {
      for (const std::int32_t w : {walls.vertex_wall[v], walls.vertex_other_wall[v]}) {
        if (w < 0) continue;
        const DemWall& wall = s.walls[static_cast<std::size_t>(w)];
        s.wall_pore_force[static_cast<std::size_t>(w)] -=
            vertex_fx_[v] * wall.nx + vertex_fy_[v] * wall.ny;
      }
    }
    std::fill(s.wall_fluid_stiffness.begin(), s.wall_fluid_stiffness.end(), 0.0);
    const double bulk = s.scene->fluid.bulk_modulus_pa;
    const auto role = s.net.flow.role();
    for (const WallPore& pore : wall_pores_) {
      const auto d = static_cast<std::size_t>(pore.domain);
      if (role[d] == DomainRole::kFixedPressure) continue;
      const double volume = StorageVolumeOf(s.net.flow, s.storage, d);
      if (volume > 0.0) {
        // What of a step's compression the pore still holds after the drain (backward Euler).
        const double held = 1.0 / (1.0 + bulk * pore.drain * dt / volume);
        s.wall_fluid_stiffness[static_cast<std::size_t>(pore.wall)] +=
            held * bulk * pore.length * pore.length / volume;
      }
    }
  }

  // With fluid weight the chord rule above pushes each wall with the heads P - W of the pores it
  // closes; the pressure on a stretch of wall is the head plus w.x along it, so the field w.x
  // integrated over every stretch a pore wets is added here: |v - u| w.(x_u + x_v) / 2 for the
  // stretch from u to v (exact: the field is linear). Without it the push on a wall would move by
  // w.x_wall per metre of wall with the origin of the scene (a wall's push must not depend on
  // where the origin is; the translation test in fluid_weight_walls_test.cc checks it).
  void AddWallWeightLoads(LiveState& s) const {
    const ParticleView v = s.step_vertices.CurrentInStep(s);
    for (const WallStretch& stretch : wetted_stretches_) {
      const auto u = static_cast<std::size_t>(stretch.from);
      const auto w = static_cast<std::size_t>(stretch.to);
      const double length = std::hypot(v.x[w] - v.x[u], v.y[w] - v.y[u]);
      // w.(x - o) at the stretch's middle, o the weight origin the heads are measured from.
      const double field = weight_->x * (0.5 * (v.x[u] + v.x[w]) - s.net.weight_origin_x_m) +
                           weight_->y * (0.5 * (v.y[u] + v.y[w]) - s.net.weight_origin_y_m);
      s.wall_pore_force[static_cast<std::size_t>(stretch.wall)] += field * length;
    }
  }

  PressureForceKernel kernel_;
  std::vector<double> slot_pressure_;  // domain pressures, then the outer arcs
  std::vector<std::int32_t> reservoir_of_boundary_pipe_;
  std::vector<double> boundary_pressure_;
  std::vector<double> arc_pressure_;
  OuterArcPressures outer_;
  std::vector<double> vertex_fx_, vertex_fy_;  // per wall vertex, the pressure force on it
  std::vector<WallPore> wall_pores_;
  std::vector<WallStretch> wetted_stretches_;  // with fluid weight only
  std::optional<FluidWeight> weight_;
  std::vector<double> node_weight_, head_;  // per flow node, with fluid weight only
};

class ApertureUpdateEffect final : public Effect {
 public:
  ApertureUpdateEffect() : Effect(kEffectKind<ApertureUpdateEffectSpec>) {}
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status Bind(LiveState& s, const EffectSet&) override {
    SEEP_ASSIGN_OR_RETURN(
        ContactApertureUpdater updater,
        ContactApertureUpdater::Create(SceneApertureLaw(*s.scene), s.scene->fluid.viscosity_pa_s));
    updater_.emplace(std::move(updater));
    return Rebind(s);
  }
  Status Rebind(LiveState& s) override {
    pair_version_ = kNoPairTable;  // the contact list may have changed: look the pairs up again
    return updater_->Bind(s.net.flow, s.net.pipe_contact);
  }

  // Per pipe: the gap and the compressive force of the DEM pair table's entry for its contact,
  // read through a pipe -> pair index kept until the DEM rebuilds its table (0 force when the
  // pair is open or pulls: an open or stretched contact takes the gap branch of the law). A
  // contact the table no longer lists has drifted apart: its gap from the positions, no force.
  Status EndOfStep(LiveState& s, const StepInfo& info) override {
    if (!info.flow_update) return Status::Ok();
    const ContactList& c = s.net.contacts;
    const DemContactForces& dem = *s.contacts;
    const std::span<const std::int32_t> pipe_contact = s.net.pipe_contact;
    const std::size_t pipes = pipe_contact.size();
    if (pair_version_ != dem.pair_table_version()) {
      SEEP_RETURN_IF_ERROR(dem.FindPairs(c.i, c.j, &pair_of_contact_));
      pair_of_pipe_.resize(pipes);
      const DomainWalls& walls = s.net.domains.walls;
      for (std::size_t p = 0; p < pipes; ++p) {
        const std::int32_t contact = pipe_contact[p];
        if (contact < 0) {
          pair_of_pipe_[p] = kNoContact;
        } else if (walls.IsWallEdge(contact)) {
          pair_of_pipe_[p] = kWallFoot;  // a particle-wall contact (stretches carry no pipe here)
        } else {
          pair_of_pipe_[p] = pair_of_contact_[static_cast<std::size_t>(contact)];
        }
      }
      pair_version_ = dem.pair_table_version();
    }
    const bool walls = !s.net.domains.walls.empty();
    if (walls) {
      s.contacts->CollectFlowWallContacts(std::numeric_limits<double>::infinity(), s.particles,
                                          &wall_contacts_, &wall_force_);
    }
    const double* x = s.particles.x.data();
    const double* y = s.particles.y.data();
    const double* r = s.particles.radius.data();
    const std::int32_t* pair_of_pipe = pair_of_pipe_.data();
    // A block of pipes at a time, straight into the law (contact_apertures.h): writes per pipe of
    // the block only, so threads change no bit.
    const auto fill = [&](std::ptrdiff_t begin, std::ptrdiff_t count, double* force, double* gap) {
      for (std::ptrdiff_t q = 0; q < count; ++q) {
        const std::ptrdiff_t p = begin + q;
        const std::int32_t k = pair_of_pipe[p];
        if (k >= 0) {
          force[q] = std::max(dem.pair_normal_force(k), 0.0);
          gap[q] = dem.pair_gap(k);
          continue;
        }
        force[q] = 0.0;
        gap[q] = 0.0;
        if (k == kNoContact) continue;  // kept
        if (k == kWallFoot) {
          FootForceAndGap(s, static_cast<std::size_t>(p), &force[q], &gap[q]);
          continue;
        }
        const auto m = static_cast<std::size_t>(pipe_contact[p]);
        const auto i = static_cast<std::size_t>(c.i[m]);
        const auto j = static_cast<std::size_t>(c.j[m]);
        // sqrt(dx^2 + dy^2), not hypot: its scaling guard costs 3x and coordinates cannot
        // overflow.
        const double dx = x[j] - x[i];
        const double dy = y[j] - y[i];
        gap[q] = std::sqrt(dx * dx + dy * dy) - (r[i] + r[j]);
      }
    };
    ++s.counters.aperture_updates;
    return updater_->UpdateByBlocks(s.net.flow, fill).status();
  }

 private:
  static constexpr std::uint64_t kNoPairTable = ~std::uint64_t{0};
  static constexpr std::int32_t kNoContact = -2;  // a pipe that stands for no contact
  static constexpr std::int32_t kWallFoot = -3;   // a pipe across a particle-wall contact

  // A foot pipe: the gap from the particle and the wall now (the DEM's formula), the compressive
  // force of the DEM's wall contact (0 when it is not listed or open), from the wall contacts
  // collected at this flow update.
  void FootForceAndGap(const LiveState& s, std::size_t p, double* force, double* gap) const {
    const DomainWalls& walls = s.net.domains.walls;
    const std::size_t e = walls.Edge(s.net.pipe_contact[p]);
    const std::int32_t particle = walls.edge_particle[e];
    const std::int32_t w = walls.edge_wall[e];
    const auto i = static_cast<std::size_t>(particle);
    const DemWall& wall = s.walls[static_cast<std::size_t>(w)];
    *gap = (s.particles.x[i] - wall.px) * wall.nx + (s.particles.y[i] - wall.py) * wall.ny -
           s.particles.radius[i];
    // The list is sorted by (particle, wall).
    std::size_t lo = 0, hi = wall_contacts_.size();
    while (lo < hi) {
      const std::size_t mid = (lo + hi) / 2;
      const bool before =
          wall_contacts_.particle[mid] < particle ||
          (wall_contacts_.particle[mid] == particle && wall_contacts_.wall[mid] < w);
      if (before) {
        lo = mid + 1;
      } else {
        hi = mid;
      }
    }
    const bool listed = lo < wall_contacts_.size() && wall_contacts_.particle[lo] == particle &&
                        wall_contacts_.wall[lo] == w;
    *force = listed ? std::max(wall_force_[lo], 0.0) : 0.0;
  }
  std::optional<ContactApertureUpdater> updater_;
  std::uint64_t pair_version_ = kNoPairTable;
  std::vector<std::int32_t> pair_of_contact_;  // DEM pair per network contact, or -1
  // DEM pair per pipe, -1 unlisted, kNoContact or kWallFoot.
  std::vector<std::int32_t> pair_of_pipe_;
  WallContactList wall_contacts_;   // the DEM's wall contacts at this flow update
  std::vector<double> wall_force_;  // and their normal forces
};

}  // namespace

std::unique_ptr<Effect> MakeFluidForcesEffect(const FluidForcesEffectSpec&) {
  return std::make_unique<FluidForcesEffect>();
}
std::unique_ptr<Effect> MakeApertureUpdateEffect(const ApertureUpdateEffectSpec&) {
  return std::make_unique<ApertureUpdateEffect>();
}

}  // namespace seep::core::effects_internal

namespace seep::core {

double FluidStableStep(const LiveState& s, double safety) {
  const DomainNetwork& d = s.net.domains;
  const DemParticles& p = s.particles;
  const StorageModel& storage = s.storage;
  const double bulk = s.scene->fluid.bulk_modulus_pa;
  FluidVertices vertices;
  const ParticleView at = vertices.Current(s);
  std::vector<double> stiffness(p.size(), 0.0);
  for (std::size_t domain = 0; domain < d.num_domains(); ++domain) {
    if (s.net.flow.role()[domain] == DomainRole::kFixedPressure) continue;
    const double volume = StorageVolumeOf(s.net.flow, storage, domain);
    if (!(volume > 0.0)) continue;
    const auto begin = static_cast<std::size_t>(d.loop_offsets[domain]);
    const auto end = static_cast<std::size_t>(d.loop_offsets[domain + 1]);
    const std::size_t n = end - begin;
    for (std::size_t k = 0; k < n; ++k) {
      const auto prev = static_cast<std::size_t>(d.loop_particles[begin + (k + n - 1) % n]);
      const auto self = static_cast<std::size_t>(d.loop_particles[begin + k]);
      const auto next = static_cast<std::size_t>(d.loop_particles[begin + (k + 1) % n]);
      if (self >= p.size()) continue;  // a wall vertex: walls do not integrate
      const double chord = 0.5 * std::hypot(at.x[next] - at.x[prev], at.y[next] - at.y[prev]);
      stiffness[self] += bulk * chord * chord / volume;
    }
  }
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (stiffness[i] > 0.0) dt = std::min(dt, safety * std::sqrt(p.mass[i] / stiffness[i]));
  }
  return dt;
}

}  // namespace seep::core
