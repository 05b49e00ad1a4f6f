#include "seep/core/flow/storage_volume.h"

#include <cmath>
#include <string>

namespace seep::core {

Status ComputeStorageVolumesInto(const FlowNetwork& network, const StorageModel& storage,
                                 std::vector<double>* out) {
  SEEP_RETURN_IF_ERROR(ValidateStorageModel(storage));
  const std::size_t n = network.num_domains();
  std::vector<double>& vs = *out;
  vs.resize(n);
  const auto role = network.role();
  for (std::size_t d = 0; d < n; ++d) {
    vs[d] = StorageVolumeOf(network, storage, d);
    if (role[d] != DomainRole::kFixedPressure && !(vs[d] > 0.0 && std::isfinite(vs[d]))) {
      return NonPositiveStorageVolume(storage, d, vs[d]);
    }
  }
  return Status::Ok();
}

Result<std::vector<double>> ComputeStorageVolumes(const FlowNetwork& network,
                                                  const StorageModel& storage) {
  std::vector<double> vs;
  SEEP_RETURN_IF_ERROR(ComputeStorageVolumesInto(network, storage, &vs));
  return vs;
}

Status NonPositiveStorageVolume(const StorageModel& storage, std::size_t domain, double volume) {
  return InvalidArgument(
      "flow.network." +
      std::string(storage.volume == StorageVolume::kPore ? "pore_volume" : "apparent_volume") +
      "[" + std::to_string(domain) + "]: storage volume of a non-fixed domain must be > 0 (got " +
      std::to_string(volume) + " with storage '" + std::string(StorageVolumeName(storage.volume)) +
      "'); set a volume floor (scene.solver.storage_floor_fraction) or fix its pressure");
}

Status ComputeStorageCapacities(const FlowNetwork& network, const StorageModel& storage,
                                double bulk_modulus, std::vector<double>* out) {
  SEEP_RETURN_IF_ERROR(ComputeStorageVolumesInto(network, storage, out));
  std::vector<double>& capacity = *out;
  const auto role = network.role();
  for (std::size_t d = 0; d < capacity.size(); ++d) {
    capacity[d] = role[d] == DomainRole::kFixedPressure ? 0.0 : capacity[d] / bulk_modulus;
  }
  return Status::Ok();
}

}  // namespace seep::core
