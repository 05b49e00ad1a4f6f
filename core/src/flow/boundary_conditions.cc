#include "seep/core/flow/boundary_conditions.h"

#include <string>

namespace seep::core {

Status FixPressure(FlowNetwork& network, std::span<const std::int32_t> domains, double pressure) {
  for (const std::int32_t d : domains) SEEP_RETURN_IF_ERROR(network.SetFixedPressure(d, pressure));
  return Status::Ok();
}

Status ApplyHydrostaticPressure(FlowNetwork& network, std::span<const std::int32_t> domains,
                                std::span<const double> elevation, const HydrostaticGradient& h) {
  if (elevation.size() != network.num_domains()) {
    return InvalidArgument("flow.hydrostatic.elevation: has " + std::to_string(elevation.size()) +
                           " entries, expected " + std::to_string(network.num_domains()) +
                           " (one per domain)");
  }
  for (const std::int32_t d : domains) {
    if (d < 0 || static_cast<std::size_t>(d) >= elevation.size()) {
      return InvalidArgument("flow.hydrostatic.domains: domain index " + std::to_string(d) +
                             " out of range [0, " + std::to_string(elevation.size()) + ")");
    }
    SEEP_RETURN_IF_ERROR(network.SetFixedPressure(d, HydrostaticPressure(h, elevation[d])));
  }
  return Status::Ok();
}

}  // namespace seep::core
