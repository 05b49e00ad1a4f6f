// Pressure remap across a re-detection of the domains (docs/physics.md §2.6): when contacts are
// lost or formed, the faces of the contact graph merge or split, and the pressures of the old
// domains are carried onto the new ones conserving the stored fluid.
//
// Matching. Both networks must come from the same particles (particle ids unchanged). A domain is
// identified by the directed contacts of its loop: half-edge i -> j of a loop has the domain on its
// left (domain loops are CCW; an island's outer loop is clockwise with its host domain on the
// left). A half-edge present in both networks has overlapping faces on its left, an old domain D
// and a new domain E, so D and E are joined. The connected groups of old and new domains so
// joined are clusters. A loop contact of the old network that bounds no loop of the new one
// (broken, or left dangling) also joins the two old domains beside it, so a domain whose loop
// contacts all broke at once still joins the face it merged into. Clusters are the groups so
// joined: each cluster covers the same region before and after (e.g. two old domains
// and their merged successor; one old domain and its two children).
//
// Rule. Every new domain of a cluster gets the storage-weighted mean pressure of the cluster's
// old domains, P = sum V_s P / sum V_s over the old domains. So a merge gives
// (V1 P1 + V2 P2)/(V1 + V2), a split gives both children the parent's P, an unchanged domain keeps
// its P, and sum V_s P over a cluster is conserved whenever the cluster's total volume is (a pure
// topology change). A new domain in no cluster with an old domain (a region that was part of the
// outside, closed by a new hull contact) gets options.unmatched_pressure, and is listed, so the
// caller can give it the pressure of what it was part of (PocketPressures); an old domain in no
// cluster with a new domain (opened to the outside) loses its fluid. Both are counted.
//
// Deterministic: the joins do not depend on their order (a cluster's root is its smallest member)
// and the sums run in domain order. O(loop entries): half-edges are looked up per origin vertex.
#pragma once

#include <cstdint>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/geometry/domain_detection.h"
#include "seep/core/status.h"

namespace seep::core {

struct PressureRemapOptions {
  StorageModel storage;             // which volume weighs the mean (V_p or V_d, times factor)
  double unmatched_pressure = 0.0;  // for new domains with no old counterpart, Pa
  // The old domains' current V_p and V_d (at least one value per old domain; e.g. a live flow
  // network's, whose particles moved since the old network was detected). Empty = the volumes
  // the old DomainNetwork was detected with.
  std::span<const double> old_pore_volume, old_apparent_volume;
};

struct PressureRemapReport {
  std::int32_t clusters = 0;       // clusters with at least one old and one new domain
  std::int32_t unmatched_new = 0;  // new domains given unmatched_pressure
  std::vector<std::int32_t> unmatched_new_domains;  // their ids, ascending
  std::int32_t unmatched_old = 0;                   // old domains whose fluid left the network
  double old_stored = 0.0;                          // sum V_s P over the old domains, m^2 Pa
  double new_stored = 0.0;                          // sum V_s P over the new domains, m^2 Pa
};

// Writes one pressure per new domain into *new_pressure (resized). old_pressure holds one value
// per old domain (extra entries, e.g. reservoir nodes after the domains, are ignored).
// A pocket born by a re-detection (an unmatched new domain) was part of the outside until a new
// contact closed it: it takes the pressure of what it opened into, the conductance-weighted mean
// of the fixed-pressure nodes its pipes reach (a reservoir, a drained wall, a fixed well), else of
// its neighbours that are not pockets; with neither it keeps the pressure it has. A pocket that is
// a fixed-pressure node (a boundary region's) keeps its boundary value. `pressure` is
// the new flow network's, remapped. Pockets do not count as each other's neighbours, so the
// result does not depend on the order they are visited in.
void PocketPressures(const FlowNetwork& flow, std::span<const std::int32_t> pockets,
                     std::span<double> pressure);

Result<PressureRemapReport> RemapPressures(const DomainNetwork& old_network,
                                           std::span<const double> old_pressure,
                                           const DomainNetwork& new_network,
                                           const PressureRemapOptions& options,
                                           std::vector<double>* new_pressure);

}  // namespace seep::core
