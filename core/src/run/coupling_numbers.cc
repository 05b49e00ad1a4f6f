// Pi_K of a coupled run (see coupling_numbers.h).
#include "seep/core/run/coupling_numbers.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "seep/core/dem/dem_contacts.h"
#include "seep/core/flow/storage_volume.h"
#include "seep/core/spec/scene_spec.h"

namespace seep::core {
namespace {

bool IsCoupled(const LiveState& s) {
  return s.moves() && s.has_network && s.scene != nullptr &&
         (HasEffect<FluidForcesEffectSpec>(*s.scene) ||
          HasEffect<VolumeChangeEffectSpec>(*s.scene));
}

// sum over the skeleton's springs of k_c l_c^2 (N m per m of thickness).
double SpringMoments(const LiveState& s) {
  const SceneSpec& scene = *s.scene;
  double kn = 0.0;
  const BondParams* bond = nullptr;
  for (const EffectSpec& e : scene.effects) {
    if (const auto* c = std::get_if<ContactsEffectSpec>(&e)) kn = c->law.kn;
    if (const auto* b = std::get_if<BondsEffectSpec>(&e)) bond = &b->params;
  }
  std::vector<DemContactRecord> contacts;
  s.contacts->CollectContacts(&contacts);
  const DemParticles& p = s.particles;
  double sum = 0.0;
  for (const DemContactRecord& c : contacts) {
    const auto i = static_cast<std::size_t>(c.i);
    const auto j = static_cast<std::size_t>(c.j);
    double k = c.gap <= 0.0 ? kn : 0.0;
    if (c.bonded && bond != nullptr) {
      k += bond->normal_stiffness * 2.0 * bond->radius_multiplier *
           std::min(p.radius[i], p.radius[j]);
    }
    const double l2 = (p.x[i] - p.x[j]) * (p.x[i] - p.x[j]) + (p.y[i] - p.y[j]) * (p.y[i] - p.y[j]);
    sum += k * l2;
  }
  return sum;
}

}  // namespace

std::optional<CouplingNumbers> MeasureCouplingNumbers(const LiveState& s) {
  if (!IsCoupled(s)) return std::nullopt;
  const FlowNetwork& flow = s.net.flow;
  double apparent = 0.0;
  double stored = 0.0;
  for (std::size_t d = 0; d < flow.num_domains(); ++d) {
    if (flow.role()[d] == DomainRole::kFixedPressure) continue;
    apparent += flow.apparent_volume()[d];
    stored += StorageVolumeOf(flow, s.storage, d);
  }
  const double moments = SpringMoments(s);
  if (!(apparent > 0.0) || !(stored > 0.0) || !(moments > 0.0)) return std::nullopt;
  CouplingNumbers out;
  out.storage_porosity = stored / apparent;
  out.skeleton_bulk_modulus_pa = moments / (4.0 * apparent);
  out.fluid_to_skeleton_stiffness =
      s.scene->fluid.bulk_modulus_pa / out.storage_porosity / out.skeleton_bulk_modulus_pa;
  return out;
}

}  // namespace seep::core
