// Topology effects: re-detection of the domains when the flow contacts change (bond breaks,
// contacts lost or made) with the pressures remapped conserving the stored fluid, and injection
// into the well domain (which follows the well through merges).
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "effect_factories.h"
#include "seep/core/log.h"
#include "seep/core/network/pressure_remap.h"

namespace seep::core::effects_internal {
namespace {

bool SamePairs(const ContactList& a, const ContactList& b) { return a.i == b.i && a.j == b.j; }

class RedetectionEffect final : public Effect {
 public:
  std::string_view Name() const override { return "redetection"; }
  std::uint32_t Hooks() const override { return kEndOfStepHook; }

  Status EndOfStep(CoupledState& s, const StepInfo& info) override {
    if (!info.flow_update) return Status::Ok();
    ++s.counters.topology_checks;
    const double max_gap = SceneContactGap(*s.scene, s.net.mean_radius_m);
    s.contacts->CollectFlowContacts(max_gap, &candidate_);
    if (SamePairs(candidate_, s.net.contacts)) return Status::Ok();

    SceneNetwork next;
    next.packing = s.net.packing;
    std::copy(s.particles.x.begin(), s.particles.x.end(), next.packing.x.begin());
    std::copy(s.particles.y.begin(), s.particles.y.end(), next.packing.y.begin());
    next.contacts = candidate_;
    next.mean_radius_m = s.net.mean_radius_m;
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

    PressureRemapOptions options;
    options.storage.volume = s.scene->solver.storage == StorageVolumeKind::kPore
                                 ? StorageVolume::kPore
                                 : StorageVolume::kApparent;
    options.unmatched_pressure = s.scene->boundary.initial_pressure_pa;
    std::vector<double> remapped;
    SEEP_ASSIGN_OR_RETURN(
        const PressureRemapReport report,
        RemapPressures(s.net.domains, s.net.flow.pressure(), fresh.domains, options, &remapped));
    // Free domains take the remapped pressure; a well under injection too (it is a source, and
    // its fluid is part of the balance); fixed nodes keep the boundary value.
    const auto roles = fresh.flow.role();
    auto pressure = fresh.flow.mutable_pressure();
    for (std::size_t d = 0; d < remapped.size(); ++d) {
      const bool injected_well =
          s.injection_rate_m2_s > 0.0 && static_cast<std::int32_t>(d) == fresh.well_domain;
      if (roles[d] == DomainRole::kFree || injected_well) pressure[d] = remapped[d];
    }
    const double scale = std::max(std::abs(report.old_stored), std::abs(report.new_stored));
    const double error = report.unmatched_new == 0 && report.unmatched_old == 0 && scale > 0.0
                             ? std::abs(report.new_stored - report.old_stored) / scale
                             : 0.0;
    s.flow.mass_balance_error = std::max(s.flow.mass_balance_error, error);
    s.flow.worst_mass_balance_error = std::max(s.flow.worst_mass_balance_error, error);
    Logger()->debug(
        "redetection at step {}: {} -> {} domains, {} clusters, {} unmatched new, {} unmatched "
        "old, stored fluid {:.17g} -> {:.17g} (relative change {:.3g})",
        info.step, s.net.domains.num_domains(), fresh.domains.num_domains(), report.clusters,
        report.unmatched_new, report.unmatched_old, report.old_stored, report.new_stored, error);
    if (s.scene->boundary.radial && fresh.well_domain < 0 && s.breakthrough_time_s < 0.0) {
      s.breakthrough_time_s = info.time_s;
      Logger()->info(
          "step {} (t = {} s): the fracture reached the outer boundary; the well is open to the "
          "outside from now on",
          info.step, info.time_s);
    }
    s.net = std::move(fresh);
    s.detection_x = s.particles.x;
    s.detection_y = s.particles.y;
    ++s.topology_version;
    return Status::Ok();
  }

 private:
  ContactList candidate_;
};

class InjectionEffect final : public Effect {
 public:
  explicit InjectionEffect(const InjectionEffectSpec& spec) : spec_(spec) {}
  std::string_view Name() const override { return "injection"; }
  std::uint32_t Hooks() const override { return 0; }  // acts on the network, not per step

  Status Bind(CoupledState& s) override {
    s.injection_rate_m2_s = spec_.rate_m2_s;
    if (s.net.well_domain < 0) return FailedPrecondition("injection: the scene has no well domain");
    SEEP_RETURN_IF_ERROR(Rebind(s));
    // The well starts from the formation's initial pressure, not the fixed well pressure.
    s.net.flow.mutable_pressure()[static_cast<std::size_t>(s.net.well_domain)] =
        s.scene->boundary.initial_pressure_pa;
    return Status::Ok();
  }
  // After a breakthrough there is no well domain: the injected fluid leaves through the
  // fracture into the outer reservoir, which holds its pressure.
  Status Rebind(CoupledState& s) override {
    if (s.net.well_domain < 0) return Status::Ok();
    ++s.counters.injection_updates;
    return s.net.flow.SetSource(s.net.well_domain, spec_.rate_m2_s);
  }

 private:
  InjectionEffectSpec spec_;
};

}  // namespace

std::unique_ptr<Effect> MakeRedetectionEffect(const RedetectionEffectSpec&) {
  return std::make_unique<RedetectionEffect>();
}
std::unique_ptr<Effect> MakeInjectionEffect(const InjectionEffectSpec& spec) {
  return std::make_unique<InjectionEffect>(spec);
}

}  // namespace seep::core::effects_internal
