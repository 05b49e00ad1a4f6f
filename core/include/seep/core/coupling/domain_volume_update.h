// Domain volumes from the current particle positions, on a fixed topology (physics.md §2.7 step
// 4), and the volume change per domain for the dV term of the pressure update (eq. 4 / R1).
//
// The loops of a DomainNetwork stay valid while the contacts that bound them persist, so between
// re-detections V_d and V_p are recomputed from the loops alone, with the formulas of
// domain_detection.h and the detector's arithmetic (same shoelace origin and summation order;
// the wedge angle is one atan2 of cross and dot rather than a difference of two edge angles), so
// at the detection positions the values agree with the detector's to round-off:
//   V_d = shoelace area of the loop's centres - areas of the islands it hosts;
//   V_p = V_d - sum_k (theta_k/2) R_k^2 + half the lens of every overlapping loop contact
//         - for each hosted island, its solid outside its outer loop + rattler correction.
// Islands are recomputed from their outer walks. Rattlers (pruned particles) are not listed in
// the DomainNetwork, so their correction (minus their disk areas, plus their lenses) is captured
// once per topology by Bind() as the difference between the detector's V_p and the loop formula;
// disks are rigid, so it changes only through the lenses of rattler overlaps (second order, below
// the overlap tolerance of the DEM) until the next detection re-binds.
//
// Which dV to use: the fluid volume change is dV_p (R1, exact conservation); for equal disks
// dV_d = dV_p exactly, and PFC's eq. 4 uses dV_d. Pass the one matching the storage model.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/coupling/particle_view.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/status.h"

namespace seep::core {

class DomainVolumeUpdater {
 public:
  // Binds to a network right after its detection, with the positions it was detected from:
  // captures the rattler correction of every domain. Call again after every re-detection.
  Status Bind(const ParticleView& particles, const DomainNetwork& network);

  // V_d and V_p (m^2 per m) of every domain of the bound network from the current positions.
  // The spans must hold network.num_domains() entries. `network` must be the one bound (same
  // domain count; checked) and its particle ids valid for `particles` (checked, O(loop length)).
  // Allocates nothing.
  Status Compute(const ParticleView& particles, const DomainNetwork& network,
                 std::span<double> apparent_volume, std::span<double> pore_volume) const;

  // Per domain: V_p(detected) - V_p(loop formula at the bind positions), m^2. Zero (to
  // round-off) for domains holding no rattler.
  std::span<const double> rattler_correction() const { return rattler_correction_; }

 private:
  Status Check(const ParticleView& particles, const DomainNetwork& network,
               std::size_t volumes) const;
  // The loop formula (islands included, rattlers not).
  void ComputeGeometric(const ParticleView& particles, const DomainNetwork& network,
                        std::span<double> apparent_volume, std::span<double> pore_volume) const;

  std::vector<double> rattler_correction_;
};

// change[d] = after[d] - before[d] (all three of equal size; InvalidArgument otherwise).
Status ComputeVolumeChange(std::span<const double> before, std::span<const double> after,
                           std::span<double> change);

}  // namespace seep::core
