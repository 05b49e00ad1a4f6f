// The fluid effects: pressure forces on the particles, the deformation (dV) term, apertures from
// the contacts, and the flow update itself (sub-cycled explicit or one implicit step per flow
// interval).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <variant>

#include "../parallel_threshold.h"
#include "effect_factories.h"
#include "seep/core/coupling/contact_apertures.h"
#include "seep/core/coupling/domain_volume_update.h"
#include "seep/core/coupling/pressure_forces.h"
#include "seep/core/flow/explicit_solver.h"
#include "seep/core/flow/implicit_solver.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/flow/time_step_limit.h"
#include "seep/core/log.h"

namespace seep::core::effects_internal {
namespace {

ParticleView CurrentView(const CoupledState& s) {
  return ParticleView{s.particles.x, s.particles.y, s.particles.radius};
}

StorageModel SceneStorage(const SceneSpec& scene) {
  StorageModel storage;
  storage.volume = scene.solver.storage == StorageVolumeKind::kPore ? StorageVolume::kPore
                                                                    : StorageVolume::kApparent;
  return storage;
}

class FluidForcesEffect final : public Effect {
 public:
  std::string_view Name() const override { return "fluid_forces"; }
  std::uint32_t Hooks() const override { return kForceHook; }

  Status Bind(CoupledState& s) override { return Rebind(s); }

  // Which reservoir node (or -1: an impermeable hull contact) each boundary pipe of the domain
  // network drains into, from the flow network's pipes past the interior ones.
  Status Rebind(CoupledState& s) override {
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
    SEEP_RETURN_IF_ERROR(kernel_.Bind(d, s.particles.size()));
    slot_pressure_.assign(kernel_.num_slots(), 0.0);
    return Status::Ok();
  }

  Status AddForces(CoupledState& s, const StepInfo&) override {
    const auto pressure = s.net.flow.pressure();
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
    kernel_.Apply(CurrentView(s), slot_pressure_.data(), s.particles.fx.data(),
                  s.particles.fy.data());
    return Status::Ok();
  }

 private:
  PressureForceKernel kernel_;
  std::vector<double> slot_pressure_;  // domain pressures, then the outer arcs
  std::vector<std::int32_t> reservoir_of_boundary_pipe_;
  std::vector<double> boundary_pressure_;
  std::vector<double> arc_pressure_;
  OuterArcPressures outer_;
};

class VolumeChangeEffect final : public Effect {
 public:
  std::string_view Name() const override { return "volume_change"; }
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status Bind(CoupledState& s) override { return Rebind(s); }
  Status Rebind(CoupledState& s) override {
    const ParticleView at_detection{s.detection_x, s.detection_y, s.particles.radius};
    SEEP_RETURN_IF_ERROR(updater_.Bind(at_detection, s.net.domains));
    const std::size_t n = s.net.domains.num_domains();
    apparent_.assign(n, 0.0);
    pore_.assign(n, 0.0);
    s.volume_change.assign(s.net.flow.num_domains(), 0.0);
    storage_ = SceneStorage(*s.scene);
    return Status::Ok();
  }

  // New volumes into the network, dV of the storage volume over the interval into the state.
  // With apparent storage V_p enters no equation of the step, so only V_d is recomputed (the
  // wedge angles and lenses of V_p are most of the cost). The network keeps the V_p of the last
  // detection or restore, capped at V_d so that it stays a valid network; every snapshot and
  // report carries V_p fresh from the positions (CompleteSnapshot), so what a checkpoint, an
  // export, a result or a state hash shows is current, and is the same for a resumed run.
  Status EndOfStep(CoupledState& s, const StepInfo& info) override {
    if (!info.flow_update) return Status::Ok();
    const bool pore = storage_.volume == StorageVolume::kPore;
    if (pore) {
      SEEP_RETURN_IF_ERROR(updater_.Compute(CurrentView(s), s.net.domains, apparent_, pore_));
    } else {
      SEEP_RETURN_IF_ERROR(updater_.ComputeApparent(CurrentView(s), s.net.domains, apparent_));
    }
    ++s.counters.volume_updates;
    const std::size_t n = apparent_.size();
    const std::span<const double> before =
        pore ? s.net.flow.pore_volume() : s.net.flow.apparent_volume();
    const std::span<const double> after = pore ? pore_ : apparent_;
    const DomainRole* role = s.net.flow.role().data();
    double* change = s.volume_change.data();
    for (std::size_t d = 0; d < n; ++d) {
      change[d] = storage_.factor * (after[d] - before[d]);
      if (!(after[d] > 0.0) && role[d] != DomainRole::kFixedPressure) {
        return FailedPrecondition(fmt::format(
            "coupling: domain {} collapsed (volume {} m^2 at step {}); the particles overlap "
            "too much: raise contacts.law.kn or lower the load",
            d, after[d], info.step));
      }
    }
    std::copy(apparent_.begin(), apparent_.end(), s.net.flow.mutable_apparent_volume().begin());
    // The domain network carries the same volumes, so that a re-detection's pressure remap
    // weighs the old domains as the flow solver stored them.
    std::copy(apparent_.begin(), apparent_.end(), s.net.domains.apparent_volume.begin());
    if (pore) {
      std::copy(pore_.begin(), pore_.end(), s.net.flow.mutable_pore_volume().begin());
      std::copy(pore_.begin(), pore_.end(), s.net.domains.pore_volume.begin());
    } else {
      const std::span<double> kept = s.net.flow.mutable_pore_volume();
      for (std::size_t d = 0; d < n; ++d) {
        kept[d] = std::min(kept[d], apparent_[d]);
        s.net.domains.pore_volume[d] = kept[d];
      }
    }
    return Status::Ok();
  }

  // V_p of the current positions into a snapshot taken with apparent storage (see EndOfStep).
  void CompleteSnapshot(const CoupledState& s, MechanicsSnapshot* out) const override {
    if (storage_.volume == StorageVolume::kPore || !s.has_network) return;
    const std::size_t n = s.net.domains.num_domains();
    std::vector<double> apparent(n), pore(n);
    const Status status = updater_.Compute(CurrentView(s), s.net.domains, apparent, pore);
    if (!status.ok()) {
      // The updater is bound to this network by construction; keep the stored V_p and say so.
      Logger()->error("coupling: snapshot keeps the detected pore volumes: {}", status.message());
      return;
    }
    std::copy(pore.begin(), pore.end(), out->pore_volume.begin());
  }

 private:
  DomainVolumeUpdater updater_;
  StorageModel storage_;
  std::vector<double> apparent_, pore_;
};

class ApertureUpdateEffect final : public Effect {
 public:
  std::string_view Name() const override { return "aperture_update"; }
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status Bind(CoupledState& s) override {
    SEEP_ASSIGN_OR_RETURN(
        ContactApertureUpdater updater,
        ContactApertureUpdater::Create(SceneApertureLaw(*s.scene), s.scene->fluid.viscosity_pa_s));
    updater_.emplace(std::move(updater));
    return Rebind(s);
  }
  Status Rebind(CoupledState& s) override {
    pair_version_ = kNoPairTable;  // the contact list may have changed: look the pairs up again
    return updater_->Bind(s.net.flow, s.net.pipe_contact);
  }

  // Per pipe: the gap and the compressive force of the DEM pair table's entry for its contact,
  // read through a pipe -> pair index kept until the DEM rebuilds its table (0 force when the
  // pair is open or pulls: an open or stretched contact takes the gap branch of the law). A
  // contact the table no longer lists has drifted apart: its gap from the positions, no force.
  Status EndOfStep(CoupledState& s, const StepInfo& info) override {
    if (!info.flow_update) return Status::Ok();
    const ContactList& c = s.net.contacts;
    const DemContactForces& dem = *s.contacts;
    const std::span<const std::int32_t> pipe_contact = s.net.pipe_contact;
    const std::size_t pipes = pipe_contact.size();
    if (pair_version_ != dem.pair_table_version()) {
      SEEP_RETURN_IF_ERROR(dem.FindPairs(c.i, c.j, &pair_of_contact_));
      pair_of_pipe_.resize(pipes);
      for (std::size_t p = 0; p < pipes; ++p) {
        const std::int32_t contact = pipe_contact[p];
        pair_of_pipe_[p] =
            contact < 0 ? kNoContact : pair_of_contact_[static_cast<std::size_t>(contact)];
      }
      pair_version_ = dem.pair_table_version();
    }
    force_.resize(pipes);
    gap_.resize(pipes);
    const double* x = s.particles.x.data();
    const double* y = s.particles.y.data();
    const double* r = s.particles.radius.data();
    const auto n = static_cast<std::ptrdiff_t>(pipes);
    // Per pipe writes only: threads change no bit.
#pragma omp parallel for schedule(static) if (n >= internal::kMinParallelItems)
    for (std::ptrdiff_t p = 0; p < n; ++p) {
      const std::int32_t k = pair_of_pipe_[p];
      if (k >= 0) {
        force_[p] = std::max(dem.pair_normal_force(k), 0.0);
        gap_[p] = dem.pair_gap(k);
        continue;
      }
      force_[p] = 0.0;
      gap_[p] = 0.0;
      if (k == kNoContact) continue;  // the updater keeps this pipe's aperture
      const auto m = static_cast<std::size_t>(pipe_contact[p]);
      const auto i = static_cast<std::size_t>(c.i[m]);
      const auto j = static_cast<std::size_t>(c.j[m]);
      // sqrt(dx^2 + dy^2), not hypot: its scaling guard costs 3x and coordinates cannot overflow.
      const double dx = x[j] - x[i];
      const double dy = y[j] - y[i];
      gap_[p] = std::sqrt(dx * dx + dy * dy) - (r[i] + r[j]);
    }
    ++s.counters.aperture_updates;
    return updater_->UpdatePerPipe(s.net.flow, force_, gap_).status();
  }

 private:
  static constexpr std::uint64_t kNoPairTable = ~std::uint64_t{0};
  static constexpr std::int32_t kNoContact = -2;  // a pipe that stands for no contact
  std::optional<ContactApertureUpdater> updater_;
  std::uint64_t pair_version_ = kNoPairTable;
  std::vector<std::int32_t> pair_of_contact_;  // DEM pair per network contact, or -1
  std::vector<std::int32_t> pair_of_pipe_;     // DEM pair per pipe, -1 unlisted, kNoContact
  std::vector<double> force_, gap_;            // per pipe
};

class FlowEffect final : public Effect {
 public:
  explicit FlowEffect(const FlowEffectSpec& spec) : spec_(spec) {}
  std::string_view Name() const override { return "flow"; }
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status Bind(CoupledState& s) override {
    const SceneSpec& scene = *s.scene;
    const StorageModel storage = SceneStorage(scene);
    if (scene.solver.kind == SolverKind::kExplicit) {
      ExplicitSolverOptions options;
      options.bulk_modulus = scene.fluid.bulk_modulus_pa;
      options.storage = storage;
      options.safety_factor = scene.solver.dt_factor;
      SEEP_ASSIGN_OR_RETURN(ExplicitSolver solver, ExplicitSolver::Create(options));
      solver_.emplace<ExplicitSolver>(std::move(solver));
    } else {
      ImplicitSolverOptions options;
      options.bulk_modulus = scene.fluid.bulk_modulus_pa;
      options.storage = storage;
      options.theta = scene.solver.kind == SolverKind::kCrankNicolson ? 0.5 : 1.0;
      SEEP_ASSIGN_OR_RETURN(ImplicitSolver solver, ImplicitSolver::Create(options));
      solver_.emplace<ImplicitSolver>(std::move(solver));
    }
    SEEP_ASSIGN_OR_RETURN(
        const CriticalTimeStep limit,
        ComputeCriticalTimeStep(s.net.flow, scene.fluid.bulk_modulus_pa, storage));
    s.flow.dt_crit_s = limit.dt_crit;
    s.flow.limiting_domain = limit.limiting_domain;
    return Status::Ok();
  }

  // DEM steps per flow update (see FlowEffectSpec::every_steps).
  std::uint64_t EverySteps(const CoupledState& s) const {
    if (spec_.every_steps > 0) return spec_.every_steps;
    // The interval also stays within the step the fluid's stiffness allows: a pressure that
    // lags the deformation by more acts as a delayed spring and pumps energy into the particles.
    const double interval =
        std::min(s.scene->solver.dt_factor * s.flow.dt_crit_s, s.fluid_limited_dt);
    const double fit = interval / s.dem_dt;
    if (!(fit >= 1.0)) return 1;
    return static_cast<std::uint64_t>(std::min(fit, 1e6));
  }

  Status EndOfStep(CoupledState& s, const StepInfo& info) override {
    if (!info.flow_update) return Status::Ok();
    const std::span<const double> dv = s.volume_change;
    double error = 0.0;
    std::int64_t sub_steps = 1;
    if (auto* explicit_solver = std::get_if<ExplicitSolver>(&solver_)) {
      SEEP_ASSIGN_OR_RETURN(const FlowAdvanceReport report,
                            explicit_solver->Advance(s.net.flow, info.flow_dt, dv));
      error = report.max_mass_balance_error;
      sub_steps = report.sub_steps;
      s.flow.dt_crit_s = report.dt_crit;
      s.flow.limiting_domain = report.limiting_domain;
      SEEP_RETURN_IF_ERROR(CheckFinite(report.last, info));
    } else {
      auto& implicit_solver = std::get<ImplicitSolver>(solver_);
      SEEP_ASSIGN_OR_RETURN(const FlowStepReport report,
                            implicit_solver.Step(s.net.flow, info.flow_dt, dv));
      error = report.mass_balance_error;
      s.flow.dt_crit_s = report.dt_crit;
      s.flow.limiting_domain = report.limiting_domain;
      SEEP_RETURN_IF_ERROR(CheckFinite(report, info));
    }
    std::fill(s.volume_change.begin(), s.volume_change.end(), 0.0);
    ++s.counters.flow_updates;
    s.counters.flow_sub_steps += static_cast<std::uint64_t>(sub_steps);
    s.flow.mass_balance_error = error;
    s.flow.worst_mass_balance_error = std::max(s.flow.worst_mass_balance_error, error);
    s.flow.last_sub_steps = sub_steps;
    s.flow.max_sub_steps = std::max(s.flow.max_sub_steps, sub_steps);
    return Status::Ok();
  }

 private:
  static Status CheckFinite(const FlowStepReport& r, const StepInfo& info) {
    if (std::isfinite(r.min_pressure) && std::isfinite(r.max_pressure)) return Status::Ok();
    return FailedPrecondition(fmt::format(
        "flow: pressure became non-finite at step {} (t = {} s); lower solver.dt_factor or use "
        "the implicit solver",
        info.step, info.time_s));
  }

  FlowEffectSpec spec_;
  std::variant<std::monostate, ExplicitSolver, ImplicitSolver> solver_;
};

}  // namespace

std::unique_ptr<Effect> MakeFluidForcesEffect(const FluidForcesEffectSpec&) {
  return std::make_unique<FluidForcesEffect>();
}
std::unique_ptr<Effect> MakeVolumeChangeEffect(const VolumeChangeEffectSpec&) {
  return std::make_unique<VolumeChangeEffect>();
}
std::unique_ptr<Effect> MakeApertureUpdateEffect(const ApertureUpdateEffectSpec&) {
  return std::make_unique<ApertureUpdateEffect>();
}
std::unique_ptr<Effect> MakeFlowEffect(const FlowEffectSpec& spec) {
  return std::make_unique<FlowEffect>(spec);
}

double FluidStableStep(const CoupledState& s, double safety) {
  const DomainNetwork& d = s.net.domains;
  const DemParticles& p = s.particles;
  const StorageModel storage = SceneStorage(*s.scene);
  const double bulk = s.scene->fluid.bulk_modulus_pa;
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
      const double chord = 0.5 * std::hypot(p.x[next] - p.x[prev], p.y[next] - p.y[prev]);
      stiffness[self] += bulk * chord * chord / volume;
    }
  }
  double dt = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (stiffness[i] > 0.0) dt = std::min(dt, safety * std::sqrt(p.mass[i] / stiffness[i]));
  }
  return dt;
}

std::uint64_t FlowEverySteps(const Effect& flow, const CoupledState& state) {
  return static_cast<const FlowEffect&>(flow).EverySteps(state);
}

}  // namespace seep::core::effects_internal
