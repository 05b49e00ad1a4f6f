// Domain volumes from the current particle positions, on a fixed topology (docs/physics.md §2.7
// step 4), and the volume change per domain for the dV term of the pressure update (eq. 4 / R1).
//
// The loops of a DomainNetwork stay valid while the contacts that bound them persist, so between
// re-detections V_d and V_p are recomputed from the loops alone, with the formulas of
// domain_detection.h and the detector's arithmetic (same shoelace origin and summation order), so
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
// Cost (the coupled step runs this at every flow update). Bind measures every wedge angle once
// with atan2; Compute then works per distinct loop contact ("edge"): the angle its edge has
// turned since Bind (a short series, atan2 only beyond 1/32 rad) and half its lens (a short
// series for overlaps shallower than R/16, LensArea beyond), in one branch-free vectorised pass.
// A wedge angle is its Bind value plus the turn of the edge into it minus the turn of the edge
// out of it, so the sector sum regroups per edge and each loop entry adds one precomputed term;
// with the sector sums at Bind (kept while the radii are those of Bind) the result equals the
// per-wedge formula to round-off. On the 9,900-disk bench bed (18,228 edges, 8,365 domains) a
// Compute takes about 0.24 ms, where an atan2 and a lens per loop entry took about 1 ms.
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
  // domain count and particle count; checked, O(1): its particle ids were checked by Bind).
  // Allocates nothing.
  Status Compute(const ParticleView& particles, const DomainNetwork& network,
                 std::span<double> apparent_volume, std::span<double> pore_volume) const;

  // V_d alone (the shoelace of Compute, bit-identical to its V_d): what apparent storage needs,
  // without the wedge angle and lens of every loop entry that V_p costs.
  Status ComputeApparent(const ParticleView& particles, const DomainNetwork& network,
                         std::span<double> apparent_volume) const;

  // Per domain: V_p(detected) - V_p(loop formula at the bind positions), m^2. Zero (to
  // round-off) for domains holding no rattler.
  std::span<const double> rattler_correction() const { return rattler_correction_; }

 private:
  Status Check(const ParticleView& particles, const DomainNetwork& network,
               std::size_t volumes) const;
  // The sector sums at the Bind angles, per domain loop and per outer walk, for given radii.
  struct SectorSums {
    std::span<const double> loop, outer;
    bool bind_radii = true;  // the radii are those of Bind (the sums are Bind's own)
  };

  // The loop formula (islands included, rattlers not); V_p (and `sectors`) only when kPore.
  template <bool kPore>
  void ComputeGeometric(const ParticleView& particles, const DomainNetwork& network,
                        const SectorSums& sectors, std::span<double> apparent_volume,
                        std::span<double> pore_volume) const;

  Status CheckBound(const DomainNetwork& network) const;
  // The distinct contacts of the loops ("edges"), each loop entry's edge and wedge angle.
  Status BindEdges(const ParticleView& particles, const DomainNetwork& network);
  // Bind's sums while the radii are Bind's (a DEM's are), else sums for these radii.
  SectorSums Sectors(const ParticleView& particles, const DomainNetwork& network) const;
  // Per edge and direction: half its lens minus its turn's share of the sector sum.
  void ComputeEdgeTerms(const ParticleView& particles, bool bind_radii) const;
  template <bool kBindRadii>
  void ComputeEdgeTermsWith(const ParticleView& particles) const;

  std::vector<double> rattler_correction_;
  // Particle count at Bind, whose ids were checked then (Compute checks only the count).
  std::size_t bound_particles_ = 0;
  // Edges: particles (lo < hi) and the vector lo -> hi at Bind.
  std::vector<std::int32_t> edge_lo_, edge_hi_;
  std::int32_t NumEdges() const { return static_cast<std::int32_t>(edge_lo_.size()); }
  std::vector<double> edge_x0_, edge_y0_;
  // Per entry of the domain loops and of the outer walks: the edge e to the next entry, or
  // NumEdges() + e if it is walked hi -> lo, the index of its term. (The wedge angles at Bind come
  // from these and the edge vectors when the radii change, see BindWedgeAngle.)
  std::vector<std::int32_t> loop_entry_term_, outer_entry_term_;
  // Radii and sector sums per face at Bind.
  std::vector<double> bind_radius_, bind_loop_sector_, bind_outer_sector_;
  // Per edge, 1/R of its particles at Bind (the lens series needs h/R): streamed, where a
  // per-particle array would cost two more gathers an edge.
  std::vector<double> edge_inv_r_lo_, edge_inv_r_hi_;
  // Scratch of Compute (so Compute allocates nothing; one updater per thread).
  mutable std::vector<double> edge_term_;
  mutable std::vector<double> loop_sector_, outer_sector_;  // Sectors() for other radii
};

// change[d] = after[d] - before[d] (all three of equal size; InvalidArgument otherwise).
Status ComputeVolumeChange(std::span<const double> before, std::span<const double> after,
                           std::span<double> change);

}  // namespace seep::core
