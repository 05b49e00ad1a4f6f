// Topology effects: re-detection of the domains when the flow contacts change (bond breaks,
// contacts lost or made) with the pressures remapped conserving the stored fluid, and injection
// into the well domain (which follows the well through merges).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <utility>

#include "effect_factories.h"
#include "seep/core/effects/effect_set.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/log.h"
#include "seep/core/network/pressure_remap.h"
#include "seep/core/network/scene_walls.h"

namespace seep::core::effects_internal {
namespace {

// sum V_s P over the domains whose fluid the books track (free and source), m^2 Pa. `source`:
// a domain that counts although the network does not show it as a source yet (a fresh
// network's injected well, made a source when the injection effect re-binds), or -1.
double HeldFluid(const FlowNetwork& flow, const StorageModel& storage, std::int32_t source) {
  const auto role = flow.role();
  const auto pressure = flow.pressure();
  double held = 0.0;
  for (std::size_t d = 0; d < flow.num_domains(); ++d) {
    if (role[d] == DomainRole::kFixedPressure && static_cast<std::int32_t>(d) != source) continue;
    held += StorageVolumeOf(flow, storage, d) * pressure[d];
  }
  return held;
}

// A boundary region that lost its last domain at a re-detection, or got one back: allowed (the
// particles moved; boundary_regions.h), but a flux region then injects nothing, so say so.
void LogEmptiedRegions(const SceneSpec& scene, const SceneNetwork& before,
                       const SceneNetwork& after, const StepInfo& info) {
  const auto& regions = scene.boundary.regions;
  for (std::size_t r = 0;
       r < regions.size() && r < before.regions.size() && r < after.regions.size(); ++r) {
    const bool was = !before.regions[r].nodes.empty();
    const bool is = !after.regions[r].nodes.empty();
    if (was == is) continue;
    Logger()->info(
        "step {} (t = {} s): boundary region {} ('{}') {} at this re-detection", info.step,
        info.time_s, r, regions[r].name,
        is ? "holds a domain again"
           : "holds no domain any more (no free domain's centroid lies in it); its condition "
             "acts on nothing until one does");
  }
}

class RedetectionEffect final : public Effect {
 public:
  RedetectionEffect() : Effect(kEffectKind<RedetectionEffectSpec>) {}
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status Bind(LiveState&, const EffectSet& effects) override {
    injected_well_ = effects.injection != nullptr;
    return Status::Ok();
  }

  Status EndOfStep(LiveState& s, const StepInfo& info) override {
    if (!info.flow_update) return Status::Ok();
    ++s.counters.topology_checks;
    const double max_gap = SceneContactGap(*s.scene, s.net.mean_radius_m);
    const bool walls = !s.net.walls.empty();
    if (walls) s.contacts->CollectFlowWallContacts(max_gap, s.particles, &wall_candidate_);
    const bool same_walls = !walls || (wall_candidate_.particle == s.net.wall_contacts.particle &&
                                       wall_candidate_.wall == s.net.wall_contacts.wall);
    // Compared on the pair table: the list is made only when it differs (a copy of every
    // contact, held between checks, was 16 bytes a contact).
    if (same_walls && s.contacts->FlowContactsAre(max_gap, s.net.contacts.i, s.net.contacts.j)) {
      return Status::Ok();
    }
    ContactList candidate;
    s.contacts->CollectFlowContacts(max_gap, &candidate);

    SceneNetwork next;
    next.packing = s.net.packing;
    std::copy(s.particles.x.begin(), s.particles.x.end(), next.packing.x.begin());
    std::copy(s.particles.y.begin(), s.particles.y.end(), next.packing.y.begin());
    next.contacts = std::move(candidate);
    if (walls) {
      next.walls = WallLines(s.walls);
      next.wall_contacts = wall_candidate_;
    }
    next.mean_radius_m = s.net.mean_radius_m;
    next.weight_origin_x_m = s.net.weight_origin_x_m;
    next.weight_origin_y_m = s.net.weight_origin_y_m;
    next.well_x_m = s.net.well_x_m;
    next.well_y_m = s.net.well_y_m;
    next.well_may_vanish = true;
    Result<SceneNetwork> built = ConnectSceneNetwork(*s.scene, std::move(next));
    if (!built.ok()) {
      return FailedPrecondition(fmt::format("redetection at step {} (t = {} s): {}", info.step,
                                            info.time_s, built.status().message()));
    }
    SceneNetwork& fresh = *built;
    ++s.counters.redetections;
    ++state_.redetections;

    PressureRemapOptions options;
    options.storage = s.storage;
    // The old domains as the flow solver stored them: their volumes moved since detection.
    options.old_pore_volume = s.net.flow.pore_volume();
    options.old_apparent_volume = s.net.flow.apparent_volume();
    options.unmatched_pressure = s.scene->boundary.initial_pressure_pa;
    std::vector<double> remapped;
    SEEP_ASSIGN_OR_RETURN(
        const PressureRemapReport report,
        RemapPressures(s.net.domains, s.net.flow.pressure(), fresh.domains, options, &remapped));
    // Free domains take the remapped pressure; sources (a flux region's domains) and a well
    // under injection too (a source from the injection's re-bind on; their fluid is part of the
    // balance); fixed nodes keep the boundary value.
    const auto roles = fresh.flow.role();
    auto pressure = fresh.flow.mutable_pressure();
    for (std::size_t d = 0; d < remapped.size(); ++d) {
      const bool injected_well =
          injected_well_ && static_cast<std::int32_t>(d) == fresh.well_domain;
      if (roles[d] != DomainRole::kFixedPressure || injected_well) pressure[d] = remapped[d];
    }
    PocketPressures(fresh.flow, report.unmatched_new_domains, pressure);
    // What the re-description created or destroyed: the fluid the free and source domains hold
    // now minus before (a conserving remap books rounding only).
    const std::int32_t fresh_well = injected_well_ ? fresh.well_domain : -1;
    const double booked =
        (HeldFluid(fresh.flow, s.storage, fresh_well) - HeldFluid(s.net.flow, s.storage, -1)) /
        s.scene->fluid.bulk_modulus_pa;
    // What the remap created or destroyed is now held by the domains: a source of the books
    // (redetection_m2) and a change of what they store (compressed_m2), so that the balance
    // closes whatever the remap did and fluid_balance_error measures the flow's own imbalance.
    // Booked as a source alone, every remap's change showed up as an imbalance of its size.
    s.books.ledger.redetection_m2 += booked;
    s.books.ledger.compressed_m2 += booked;
    s.books.ledger.handled_m2 += std::abs(booked);
    const double scale = std::max(std::abs(report.old_stored), std::abs(report.new_stored));
    const double error = report.unmatched_new == 0 && report.unmatched_old == 0 && scale > 0.0
                             ? std::abs(report.new_stored - report.old_stored) / scale
                             : 0.0;
    s.books.step_error = std::max(s.books.step_error, error);
    s.books.worst_error = std::max(s.books.worst_error, error);
    Logger()->debug(
        "redetection at step {}: {} -> {} domains, {} clusters, {} unmatched new, {} unmatched "
        "old, stored fluid {:.17g} -> {:.17g} (relative change {:.3g})",
        info.step, s.net.domains.num_domains(), fresh.domains.num_domains(), report.clusters,
        report.unmatched_new, report.unmatched_old, report.old_stored, report.new_stored, error);
    const bool through = fresh.well_domain < 0 || fresh.well_on_wall;
    if (s.scene->boundary.radial && through && state_.breakthrough_time_s < 0.0) {
      state_.breakthrough_time_s = info.time_s;
      Logger()->info(
          "step {} (t = {} s): the fracture reached the outer boundary; the well is open to it "
          "from now on",
          info.step, info.time_s);
    }
    LogEmptiedRegions(*s.scene, s.net, fresh, info);
    s.net = std::move(fresh);
    s.detection_x = s.particles.x;
    s.detection_y = s.particles.y;
    ++s.topology_version;
    return Status::Ok();
  }

  void SaveTo(EffectStates* out) const override { out->redetection = state_; }
  void RestoreFrom(const EffectStates& in) override { state_ = in.redetection; }
  void AddMetrics(const LiveState&, Metrics* m) const override {
    if (state_.breakthrough_time_s >= 0.0) (*m)["breakthrough_time_s"] = state_.breakthrough_time_s;
    (*m)["redetections"] = static_cast<double>(state_.redetections);
  }

 private:
  WallContactList wall_candidate_;
  bool injected_well_ = false;  // the well is a source (injection): it takes the remapped pressure
  RedetectionEffectState state_;
};

class InjectionEffect final : public EffectWithSpec<InjectionEffectSpec> {
 public:
  using EffectWithSpec::EffectWithSpec;
  // The source acts on the network (set at bind and re-bind); at the end of a flow update the
  // effect tracks the well pressure's peak, the breakdown pressure.
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status Bind(LiveState& s, const EffectSet&) override {
    if (s.net.well_domain < 0) return FailedPrecondition("injection: the scene has no well domain");
    SEEP_RETURN_IF_ERROR(Rebind(s));
    // The well starts from the formation's initial pressure, not the fixed well pressure.
    s.net.flow.mutable_pressure()[static_cast<std::size_t>(s.net.well_domain)] =
        s.scene->boundary.initial_pressure_pa;
    return Status::Ok();
  }
  // After a breakthrough there is no well domain: the injected fluid leaves through the
  // fracture into the outer reservoir, which holds its pressure.
  // The rate is the live scene's: a stage may shut the well in (0) or change the rate.
  Status Rebind(LiveState& s) override {
    if (s.net.well_domain < 0) return Status::Ok();
    ++s.counters.injection_updates;
    return s.net.flow.SetSource(s.net.well_domain,
                                FindEffect<InjectionEffectSpec>(*s.scene)->rate_m2_s);
  }
  Status Reconfigure(LiveState& s) override { return Rebind(s); }

  Status EndOfStep(LiveState& s, const StepInfo& info) override {
    if (!info.flow_update || s.net.well_domain < 0) return Status::Ok();
    const double well = s.net.flow.pressure()[static_cast<std::size_t>(s.net.well_domain)];
    if (well > state_.peak_well_pressure_pa) {
      state_.peak_well_pressure_pa = well;
      state_.peak_well_time_s = info.time_s;
    }
    return Status::Ok();
  }

  void SaveTo(EffectStates* out) const override { out->injection = state_; }
  void RestoreFrom(const EffectStates& in) override { state_ = in.injection; }
  void AddMetrics(const LiveState& s, Metrics* m) const override {
    (*m)["breakdown_pressure_pa"] = state_.peak_well_pressure_pa;
    (*m)["breakdown_time_s"] = state_.peak_well_time_s;
    if (s.net.well_domain >= 0) {
      (*m)["well_pressure_pa"] = s.net.flow.pressure()[static_cast<std::size_t>(s.net.well_domain)];
    }
  }
  // The well's pressure as it rises to the breakdown and falls after it (the breakdown is read off
  // this curve); after a breakthrough the outer reservoir's, which the well then is.
  void AddSeriesColumns(const LiveState&, std::vector<std::string>* columns) const override {
    columns->push_back("well_pressure_pa");
  }
  void AddSample(const LiveState& s, std::vector<double>* row) const override {
    row->push_back(WellPressure(s.net).value_or(s.scene->boundary.initial_pressure_pa));
  }

 private:
  InjectionEffectState state_;
};

}  // namespace

std::unique_ptr<Effect> MakeRedetectionEffect(const RedetectionEffectSpec&) {
  return std::make_unique<RedetectionEffect>();
}
std::unique_ptr<Effect> MakeInjectionEffect(const InjectionEffectSpec& spec) {
  return std::make_unique<InjectionEffect>(spec);
}

}  // namespace seep::core::effects_internal
