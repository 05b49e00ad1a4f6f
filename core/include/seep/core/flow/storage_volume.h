// Per-domain storage volume V_s = max(factor * (V_d or V_p), floor), the volume in the denominator
// of the pressure update (docs/physics.md §1.2, R1/R2). Fixed-pressure domains store nothing the
// solvers use; every other domain must have V_s > 0 or its pressure update is undefined.
#pragma once

#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/status.h"

namespace seep::core {

// V_s of a domain of volume v (its V_d or V_p, as the model says), m^2: std::max(factor v, floor)
// written on values, so that a loop of it vectorises (std::max returns a reference).
inline double StorageVolumeFrom(double v, double factor, double floor) {
  const double scaled = factor * v;
  return scaled < floor ? floor : scaled;
}

// V_s of domain d, m^2 (no checks).
inline double StorageVolumeOf(const FlowNetwork& network, const StorageModel& storage,
                              std::size_t d) {
  const double v = storage.volume == StorageVolume::kPore ? network.pore_volume()[d]
                                                          : network.apparent_volume()[d];
  return StorageVolumeFrom(v, storage.factor, storage.floor_m2);
}

// V_s for every domain. Fails with InvalidArgument naming the domain when a free or source domain
// has V_s <= 0 (a sliver or an unset volume without a floor, docs/physics.md §4.4).
Result<std::vector<double>> ComputeStorageVolumes(const FlowNetwork& network,
                                                  const StorageModel& storage);
// The same into *out, which keeps its allocation from call to call (a solver's per-step refresh).
Status ComputeStorageVolumesInto(const FlowNetwork& network, const StorageModel& storage,
                                 std::vector<double>* out);

// The error for a free or source domain whose V_s is not > 0 (names the volume field and domain).
Status NonPositiveStorageVolume(const StorageModel& storage, std::size_t domain, double volume);

// Storage capacity V_s/K_f (m^2/Pa) of every domain into *out, 0 for fixed-pressure domains: the
// coefficient of dP/dt in every pressure update. Same checks as ComputeStorageVolumes; *out keeps
// its allocation from call to call (the implicit solver's per-step refresh).
Status ComputeStorageCapacities(const FlowNetwork& network, const StorageModel& storage,
                                double bulk_modulus, std::vector<double>* out);

}  // namespace seep::core
