// FluidTally: what one flow update moved, summed over its (sub-)steps, in m^2 per m of thickness
// at the reference density. The run's cumulative books (effects/fluid_ledger.h) add these up.
//
// Every term is the scheme's own: the boundary flux each step transports (explicit: at the old
// pressures; theta method: theta at the new plus 1 - theta at the old), the stored change from
// the pressures before and after the step (sum V_s dP / K_f over the non-fixed domains), the dV
// and the sources it was given. So for every update
//   compressed + pore_growth = source + sum over fixed nodes of (-node_outflow)
// up to rounding, whatever the network's topology.
#pragma once

#include <cstddef>
#include <vector>

namespace seep::core {

struct FluidTally {
  double source_m2 = 0.0;       // sum dt Q_src over the source domains
  double compressed_m2 = 0.0;   // sum V_s dP / K_f over the non-fixed domains
  double pore_growth_m2 = 0.0;  // sum dV over the non-fixed domains
  // Per flow node: what left the network into it, sum dt x (its net inflow from the network);
  // non-zero only for fixed-pressure nodes.
  std::vector<double> node_outflow_m2;
  // sum dt |flux| over the fixed nodes, step by step: the fluid the boundaries exchanged.
  double boundary_gross_m2 = 0.0;

  // Zeroes the totals for a network of `nodes` flow nodes.
  void Reset(std::size_t nodes) {
    source_m2 = compressed_m2 = pore_growth_m2 = boundary_gross_m2 = 0.0;
    node_outflow_m2.assign(nodes, 0.0);
  }
};

}  // namespace seep::core
