// Read-only measurements on a network at its current pressures: boundary fluxes, the fluid mass
// proxy, pressure range, and the Darcy permeability of a permeameter run (docs/physics.md §3.1).
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/status.h"

namespace seep::core {

struct BoundaryFluxes {
  // One entry per fixed-pressure domain that has at least one pipe to a non-fixed domain, in
  // domain order: the rate at which fluid leaves that node into the network (m^2/s; negative =
  // the network drains into it).
  std::vector<std::int32_t> domain;
  std::vector<double> inflow;
  double total_inflow = 0.0;   // sum of the positive entries, m^2/s
  double total_outflow = 0.0;  // minus the sum of the negative entries (>= 0), m^2/s
  double net_inflow = 0.0;     // total_inflow - total_outflow
};

// Pipes between two fixed nodes carry flow but do not touch the network's unknowns: excluded.
BoundaryFluxes ComputeBoundaryFluxes(const FlowNetwork& network);

// The rate (m^2/s) at which fluid leaves fixed-pressure node `node` into the network; 0 when no
// pipe joins it to a non-fixed domain (or node < 0).
double NodeInflow(const BoundaryFluxes& fluxes, std::int32_t node);

// sum over non-fixed domains of V_s P / K_f (m^2): the part of the fluid mass proxy that changes.
Result<double> StoredFluidExcess(const FlowNetwork& network, double bulk_modulus,
                                 const StorageModel& storage);
// The fluid mass proxy sum V_s (1 + P/K_f) over non-fixed domains (m^2, mass / rho_ref).
Result<double> FluidMassProxy(const FlowNetwork& network, double bulk_modulus,
                              const StorageModel& storage);

struct PressureRange {
  double min = 0.0;
  double max = 0.0;
  std::int32_t argmin = -1;
  std::int32_t argmax = -1;
};
PressureRange ComputePressureRange(const FlowNetwork& network);

// sum P V / sum V over every domain, V the domain's pore (kPore) or apparent (kApparent) volume:
// the sample-mean pressure an undrained or consolidation measurement reads (Pa; NaN when the
// volumes sum to 0).
double VolumeWeightedMeanPressure(const FlowNetwork& network, StorageVolume weight);

// k = mu Q L / (H dp), m^2: Darcy permeability from the flow rate Q (m^2/s per unit thickness)
// through a sample of length L along the flow and height H across it under a drop dp (Pa).
Result<double> DarcyPermeability(double viscosity, double flow_rate, double length, double height,
                                 double pressure_drop);

}  // namespace seep::core
