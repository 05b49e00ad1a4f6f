#include "seep/core/flow/fluid.h"

#include <cmath>
#include <string>

namespace seep::core {

std::string_view StorageVolumeName(StorageVolume volume) {
  switch (volume) {
    case StorageVolume::kApparent:
      return "apparent";
    case StorageVolume::kPore:
      return "pore";
  }
  return "unknown";
}

namespace {
Status RequirePositive(const char* field, double value) {
  if (std::isfinite(value) && value > 0.0) return Status::Ok();
  return InvalidArgument(std::string(field) + ": must be finite and > 0 (got " +
                         std::to_string(value) + ")");
}
}  // namespace

Status ValidateFluidProperties(const FluidProperties& fluid) {
  SEEP_RETURN_IF_ERROR(RequirePositive("flow.fluid.viscosity", fluid.viscosity));
  return RequirePositive("flow.fluid.bulk_modulus", fluid.bulk_modulus);
}

Status ValidateStorageModel(const StorageModel& storage) {
  if (storage.volume != StorageVolume::kApparent && storage.volume != StorageVolume::kPore) {
    return InvalidArgument("flow.storage.volume: unknown storage volume kind");
  }
  SEEP_RETURN_IF_ERROR(RequirePositive("flow.storage.factor", storage.factor));
  if (!(std::isfinite(storage.floor_m2) && storage.floor_m2 >= 0.0)) {
    return InvalidArgument("flow.storage.floor_m2: must be finite and >= 0");
  }
  return Status::Ok();
}

}  // namespace seep::core
