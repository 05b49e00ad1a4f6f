// Validation of the parallel-bond parameters (the bond update itself is inline in the header).
#include "seep/core/dem/parallel_bond.h"

#include <cmath>
#include <string>

namespace seep::core {

Status ValidateBondParams(const BondParams& p) {
  struct Field {
    const char* name;
    double value;
    bool strictly_positive;
  };
  const Field fields[] = {{"normal_stiffness", p.normal_stiffness, true},
                          {"shear_stiffness", p.shear_stiffness, false},
                          {"radius_multiplier", p.radius_multiplier, true},
                          {"tensile_strength", p.tensile_strength, true},
                          {"shear_strength", p.shear_strength, true}};
  for (const Field& f : fields) {
    const bool ok = std::isfinite(f.value) && (f.strictly_positive ? f.value > 0.0 : f.value >= 0);
    if (!ok) {
      return InvalidArgument(std::string("dem.bond.") + f.name + ": must be finite and " +
                             (f.strictly_positive ? "> 0" : ">= 0") + " (got " +
                             std::to_string(f.value) + ")");
    }
  }
  return Status::Ok();
}

}  // namespace seep::core
