// Fluid constants and the storage model shared by every pressure solver of the flow area.
//
// Units are SI per unit out-of-plane thickness (2D): volumes in m^2, rates in m^2/s, pressures in
// Pa. The thickness cancels in every equation of the pipe-network model (docs/physics.md §1.2).
#pragma once

#include <string_view>

#include "seep/core/status.h"

namespace seep::core {

struct FluidProperties {
  double viscosity = 1e-3;    // mu, Pa s (water).
  double bulk_modulus = 2e9;  // K_f, Pa (water is 2.2e9; often scaled down, docs/physics.md §4.4).
};

// Which per-domain volume stores fluid in the pressure update (docs/physics.md §1.2, eq. R1/R2):
//   kApparent: V_s = factor * V_d, the original PFC eq. 4 (overstates storage by 1/n_s);
//   kPore:     V_s = factor * V_p, exact flow conservation for factor = 1.
// `factor` is the optional storage factor (e.g. n_target/n_2D to match a real material).
enum class StorageVolume { kApparent, kPore };

struct StorageModel {
  StorageVolume volume = StorageVolume::kPore;
  double factor = 1.0;
  // Volume floor (docs/physics.md §4.4 remedy 1): V_s = max(factor x V, floor_m2), m^2. Adds
  // storage to slivers only; steady states do not change and the books stay closed, since every
  // update and every balance uses the same V_s. 0 = none.
  double floor_m2 = 0.0;
};

std::string_view StorageVolumeName(StorageVolume volume);

// Messages name the field, e.g. "flow.fluid.bulk_modulus: must be finite and > 0 (got 0)".
Status ValidateFluidProperties(const FluidProperties& fluid);
Status ValidateStorageModel(const StorageModel& storage);

}  // namespace seep::core
