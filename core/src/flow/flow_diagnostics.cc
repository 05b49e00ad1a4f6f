#include "seep/core/flow/flow_diagnostics.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "seep/core/flow/pipe_head.h"
#include "seep/core/flow/storage_volume.h"

namespace seep::core {

BoundaryFluxes ComputeBoundaryFluxes(const FlowNetwork& network) {
  const std::size_t nd = network.num_domains();
  const auto role = network.role();
  const auto pa = network.pipe_domain_a();
  const auto pb = network.pipe_domain_b();
  const auto c = network.pipe_conductance();
  std::vector<double> per_domain(nd, 0.0);
  std::vector<std::uint8_t> touched(nd, 0);
  for (std::size_t p = 0; p < c.size(); ++p) {
    const bool fa = role[pa[p]] == DomainRole::kFixedPressure;
    const bool fb = role[pb[p]] == DomainRole::kFixedPressure;
    if (fa == fb) continue;
    const std::int32_t fixed = fa ? pa[p] : pb[p];
    const double into_a = PipeInflowToA(network, p);  // the head included (pipe_head.h)
    per_domain[fixed] += fa ? -into_a : into_a;
    touched[fixed] = 1;
  }
  BoundaryFluxes out;
  for (std::size_t d = 0; d < nd; ++d) {
    if (!touched[d]) continue;
    out.domain.push_back(static_cast<std::int32_t>(d));
    out.inflow.push_back(per_domain[d]);
    if (per_domain[d] > 0.0) {
      out.total_inflow += per_domain[d];
    } else {
      out.total_outflow -= per_domain[d];
    }
  }
  out.net_inflow = out.total_inflow - out.total_outflow;
  return out;
}

Result<double> StoredFluidExcess(const FlowNetwork& network, double bulk_modulus,
                                 const StorageModel& storage) {
  if (!(std::isfinite(bulk_modulus) && bulk_modulus > 0.0)) {
    return InvalidArgument("flow.fluid.bulk_modulus: must be finite and > 0");
  }
  SEEP_ASSIGN_OR_RETURN(std::vector<double> vs, ComputeStorageVolumes(network, storage));
  const auto role = network.role();
  const auto pressure = network.pressure();
  double sum = 0.0;
  for (std::size_t d = 0; d < vs.size(); ++d) {
    if (role[d] != DomainRole::kFixedPressure) sum += vs[d] * pressure[d];
  }
  return sum / bulk_modulus;
}

Result<double> FluidMassProxy(const FlowNetwork& network, double bulk_modulus,
                              const StorageModel& storage) {
  SEEP_ASSIGN_OR_RETURN(double excess, StoredFluidExcess(network, bulk_modulus, storage));
  SEEP_ASSIGN_OR_RETURN(std::vector<double> vs, ComputeStorageVolumes(network, storage));
  const auto role = network.role();
  double volume = 0.0;
  for (std::size_t d = 0; d < vs.size(); ++d) {
    if (role[d] != DomainRole::kFixedPressure) volume += vs[d];
  }
  return volume + excess;
}

PressureRange ComputePressureRange(const FlowNetwork& network) {
  PressureRange out;
  const auto pressure = network.pressure();
  for (std::size_t d = 0; d < pressure.size(); ++d) {
    if (out.argmin < 0 || pressure[d] < out.min) {
      out.min = pressure[d];
      out.argmin = static_cast<std::int32_t>(d);
    }
    if (out.argmax < 0 || pressure[d] > out.max) {
      out.max = pressure[d];
      out.argmax = static_cast<std::int32_t>(d);
    }
  }
  return out;
}

double VolumeWeightedMeanPressure(const FlowNetwork& network, StorageVolume weight) {
  const auto pressure = network.pressure();
  const auto volume =
      weight == StorageVolume::kPore ? network.pore_volume() : network.apparent_volume();
  double pv = 0.0, v = 0.0;
  for (std::size_t d = 0; d < pressure.size(); ++d) {
    pv += pressure[d] * volume[d];
    v += volume[d];
  }
  return v > 0.0 ? pv / v : std::numeric_limits<double>::quiet_NaN();
}

Result<double> DarcyPermeability(double viscosity, double flow_rate, double length, double height,
                                 double pressure_drop) {
  auto positive = [](const char* field, double v) -> Status {
    if (std::isfinite(v) && v > 0.0) return Status::Ok();
    return InvalidArgument(std::string("flow.darcy.") + field + ": must be finite and > 0 (got " +
                           std::to_string(v) + ")");
  };
  SEEP_RETURN_IF_ERROR(positive("viscosity", viscosity));
  SEEP_RETURN_IF_ERROR(positive("length", length));
  SEEP_RETURN_IF_ERROR(positive("height", height));
  if (!(std::isfinite(pressure_drop) && pressure_drop != 0.0)) {
    return InvalidArgument("flow.darcy.pressure_drop: must be finite and non-zero (got " +
                           std::to_string(pressure_drop) + ")");
  }
  if (!std::isfinite(flow_rate)) return InvalidArgument("flow.darcy.flow_rate: must be finite");
  return viscosity * flow_rate * length / (height * pressure_drop);
}

double NodeInflow(const BoundaryFluxes& fluxes, std::int32_t node) {
  const auto it = std::lower_bound(fluxes.domain.begin(), fluxes.domain.end(), node);
  if (it == fluxes.domain.end() || *it != node) return 0.0;
  return fluxes.inflow[static_cast<std::size_t>(it - fluxes.domain.begin())];
}

}  // namespace seep::core
