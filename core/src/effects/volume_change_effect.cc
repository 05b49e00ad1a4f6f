#include "seep/core/effects/volume_change_effect.h"

#include <fmt/format.h>

#include <algorithm>

#include "../parallel_threshold.h"
#include "seep/core/effects/fluid_vertices.h"
#include "seep/core/log.h"

namespace seep::core {

namespace {

// dV of the domains [begin, end) (not scaled by the storage factor: the disks are rigid, so all of
// a domain's volume change is pore volume, docs/physics.md §1.2, R2: dP = K_f/(n V_d) (sum q dt -
// dV_d)); returns how many collapsed, branch-free.
double VolumeChangeRange(std::ptrdiff_t begin, std::ptrdiff_t end, const double* __restrict before,
                         const double* __restrict after, const DomainRole* __restrict role,
                         double* __restrict change) {
  double collapsed = 0.0;
#pragma omp simd reduction(+ : collapsed)
  for (std::ptrdiff_t d = begin; d < end; ++d) {
    change[d] = after[d] - before[d];
    collapsed += ((after[d] > 0.0) | (role[d] == DomainRole::kFixedPressure)) ? 0.0 : 1.0;
  }
  return collapsed;
}

// The network's live volumes of the domains [begin, end).
void LiveVolumesRange(std::ptrdiff_t begin, std::ptrdiff_t end, bool pore,
                      const double* __restrict apparent, const double* __restrict pore_now,
                      double* __restrict live_apparent, double* __restrict live_pore) {
#pragma omp simd
  for (std::ptrdiff_t d = begin; d < end; ++d) {
    live_apparent[d] = apparent[d];
    live_pore[d] = pore ? pore_now[d] : std::min(live_pore[d], apparent[d]);
  }
}

}  // namespace

Status VolumeChangeEffect::Bind(LiveState& s, const EffectSet&) { return Rebind(s); }

Status VolumeChangeEffect::Rebind(LiveState& s) {
  // The vertices at detection live as long as the Bind: a member held them, a copy of every
  // particle's position and radius (24 bytes a particle), for the whole run.
  FluidVertices at_detection;
  SEEP_RETURN_IF_ERROR(updater_.Bind(at_detection.AtDetection(s), s.net.domains));
  const std::size_t n = s.net.domains.num_domains();
  apparent_.assign(n, 0.0);
  pore_.assign(n, 0.0);
  change_.assign(s.net.flow.num_domains(), 0.0);
  return Status::Ok();
}

// New volumes into the network, dV of the storage volume over the interval into change_. With
// apparent storage V_p enters no equation of the step, so only V_d is recomputed (the wedge
// angles and lenses of V_p are most of the cost). The network keeps the V_p of the last detection
// or restore, capped at V_d so that it stays a valid network; every snapshot and report carries
// V_p fresh from the positions (ReportedPoreVolumes), so what a checkpoint, an export, a result or
// a state hash shows is current, and is the same for a resumed run.
Status VolumeChangeEffect::UpdateFlow(LiveState& s, const StepInfo& info) {
  if (!info.flow_update) return Status::Ok();
  const bool pore = s.storage.volume == StorageVolume::kPore;
  if (pore) {
    SEEP_RETURN_IF_ERROR(
        updater_.Compute(s.step_vertices.CurrentInStep(s), s.net.domains, apparent_, pore_));
  } else {
    SEEP_RETURN_IF_ERROR(
        updater_.ComputeApparent(s.step_vertices.CurrentInStep(s), s.net.domains, apparent_));
  }
  ++s.counters.volume_updates;
  const auto n = static_cast<std::ptrdiff_t>(apparent_.size());
  const double* before = (pore ? s.net.flow.pore_volume() : s.net.flow.apparent_volume()).data();
  const double* after = pore ? pore_.data() : apparent_.data();
  const DomainRole* role = s.net.flow.role().data();
  double* change = change_.data();
  // Per domain only: threads change no bit. A collapsed domain is counted branch-free and named
  // by a scan only when there is one.
  const double collapsed =
      internal::SumOverShares(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
        return VolumeChangeRange(begin, end, before, after, role, change);
      });
  for (std::ptrdiff_t d = 0; collapsed > 0.0 && d < n; ++d) {
    if (!(after[d] > 0.0) && role[d] != DomainRole::kFixedPressure) {
      return FailedPrecondition(fmt::format(
          "coupling: domain {} collapsed (volume {} m^2 at step {}); the particles overlap "
          "too much: raise contacts.law.kn or lower the load",
          d, after[d], info.step));
    }
  }
  // The flow network holds the live volumes (the domain network keeps those it was detected
  // with, which the updater measures the turns from).
  const double* apparent = apparent_.data();
  double* live_apparent = s.net.flow.mutable_apparent_volume().data();
  double* live_pore = s.net.flow.mutable_pore_volume().data();
  const double* pore_now = pore_.data();
  internal::ForEachShare(n, [&](std::ptrdiff_t begin, std::ptrdiff_t end) {
    LiveVolumesRange(begin, end, pore, apparent, pore_now, live_apparent, live_pore);
  });
  return Status::Ok();
}

std::vector<double> ReportedPoreVolumes(const LiveState& s,
                                        const VolumeChangeEffect* volume_change) {
  if (volume_change != nullptr) return volume_change->CurrentPoreVolumes(s);
  const auto kept = s.net.flow.pore_volume();
  return {kept.begin(), kept.end()};
}

std::vector<double> VolumeChangeEffect::CurrentPoreVolumes(const LiveState& s) const {
  const auto kept = s.net.flow.pore_volume();
  std::vector<double> out(kept.begin(), kept.end());
  if (s.storage.volume == StorageVolume::kPore || !s.has_network) return out;
  const std::size_t n = s.net.domains.num_domains();
  std::vector<double> apparent(n), pore(n);
  FluidVertices now;
  const Status status = updater_.Compute(now.Current(s), s.net.domains, apparent, pore);
  if (!status.ok()) {
    // The updater is bound to this network by construction; keep the stored V_p and say so.
    Logger()->error("coupling: snapshot keeps the detected pore volumes: {}", status.message());
    return out;
  }
  std::copy(pore.begin(), pore.end(), out.begin());
  return out;
}

}  // namespace seep::core
