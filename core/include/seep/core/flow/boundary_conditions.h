// Boundary conditions on a FlowNetwork, expressed through domain roles (flow_network.h):
//   fixed pressure (Dirichlet)   -> role kFixedPressure, pressure held;
//   injection rate Q_src (m^2/s) -> role kSource;
//   no flow                      -> the default: no pipe crosses an impermeable side;
//   hydrostatic                  -> fixed pressure p = p_ref + rho g (y_ref - y) per domain.
#pragma once

#include <cstdint>
#include <span>

#include "seep/core/flow/flow_network.h"
#include "seep/core/status.h"

namespace seep::core {

// Fixes every listed domain at the same pressure (Pa).
Status FixPressure(FlowNetwork& network, std::span<const std::int32_t> domains, double pressure);

struct HydrostaticGradient {
  double reference_pressure = 0.0;   // p_ref, Pa, at elevation y_ref
  double reference_elevation = 0.0;  // y_ref, m
  double density = 1000.0;           // rho, kg/m^3
  double gravity = 9.81;             // g, m/s^2 (acting towards -y)
};

inline double HydrostaticPressure(const HydrostaticGradient& h, double elevation) {
  return h.reference_pressure + h.density * h.gravity * (h.reference_elevation - elevation);
}

// Fixes each listed domain d at HydrostaticPressure(h, elevation[d]); elevation holds one value per
// domain of the network (e.g. the domain centroid y), m.
Status ApplyHydrostaticPressure(FlowNetwork& network, std::span<const std::int32_t> domains,
                                std::span<const double> elevation, const HydrostaticGradient& h);

}  // namespace seep::core
