#include "seep/core/flow/aperture_law.h"

#include <cmath>
#include <string>

namespace seep::core {

namespace {
std::string Got(double v) { return " (got " + std::to_string(v) + ")"; }
}  // namespace

Status ValidateApertureLaw(const ApertureLaw& law) {
  if (!(std::isfinite(law.residual_aperture) && law.residual_aperture > 0.0)) {
    return InvalidArgument("flow.aperture_law.residual_aperture: must be finite and > 0" +
                           Got(law.residual_aperture));
  }
  if (!(std::isfinite(law.reference_force) && law.reference_force > 0.0)) {
    return InvalidArgument("flow.aperture_law.reference_force: must be finite and > 0" +
                           Got(law.reference_force));
  }
  if (!(std::isfinite(law.gap_multiplier) && law.gap_multiplier >= 0.0)) {
    return InvalidArgument("flow.aperture_law.gap_multiplier: must be finite and >= 0" +
                           Got(law.gap_multiplier));
  }
  if (std::isnan(law.max_aperture) || law.max_aperture < law.residual_aperture) {
    return InvalidArgument("flow.aperture_law.max_aperture: must be >= residual_aperture" +
                           Got(law.max_aperture));
  }
  return Status::Ok();
}

Status FillAperturesAndConductances(const ApertureLaw& law, double viscosity,
                                    std::span<const double> normal_force,
                                    std::span<const double> gap, std::span<const double> length,
                                    std::span<double> aperture, std::span<double> conductance) {
  SEEP_RETURN_IF_ERROR(ValidateApertureLaw(law));
  if (!(std::isfinite(viscosity) && viscosity > 0.0)) {
    return InvalidArgument("flow.fluid.viscosity: must be finite and > 0" + Got(viscosity));
  }
  const std::size_t n = normal_force.size();
  if (gap.size() != n || length.size() != n || aperture.size() != n || conductance.size() != n) {
    return InvalidArgument(
        "flow.aperture_law: normal_force, gap, length, aperture and conductance must have the "
        "same size (" +
        std::to_string(n) + ", " + std::to_string(gap.size()) + ", " +
        std::to_string(length.size()) + ", " + std::to_string(aperture.size()) + ", " +
        std::to_string(conductance.size()) + ")");
  }
  for (std::size_t p = 0; p < n; ++p) {
    if (!(std::isfinite(length[p]) && length[p] > 0.0)) {
      return InvalidArgument("flow.aperture_law.length[" + std::to_string(p) +
                             "]: must be finite and > 0" + Got(length[p]));
    }
    if (!std::isfinite(normal_force[p])) {
      return InvalidArgument("flow.aperture_law.normal_force[" + std::to_string(p) +
                             "]: must be finite" + Got(normal_force[p]));
    }
    if (!std::isfinite(gap[p])) {
      return InvalidArgument("flow.aperture_law.gap[" + std::to_string(p) + "]: must be finite" +
                             Got(gap[p]));
    }
  }
  for (std::size_t p = 0; p < n; ++p) {
    const double a = Aperture(law, normal_force[p], gap[p]);
    aperture[p] = a;
    conductance[p] = PipeConductance(a, viscosity, length[p]);
  }
  return Status::Ok();
}

}  // namespace seep::core
