// The head term of the pipe law when the fluid has weight (flow_network.h, pipe_head_offset):
//
//   q_p = C_p (P_b - P_a - offset_p)   from b into a,   offset_p = rho_f g.(x_b - x_a).
//
// Between two coefficient changes the offset part -C_p offset_p is a constant per pipe, so what it
// adds to each domain's inflow is a constant per domain. The solvers add that vector like a
// source term instead of carrying a third array through their pipe loops: the explicit sweep
// keeps its 16 B per pipe, and the implicit and steady systems keep their matrix (the head moves
// only the right-hand side).
#pragma once

#include <cstddef>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"

namespace seep::core {

// Per domain: sum over its pipes of the head part of the inflow, m^2/s (zeros when the network
// has no head offsets). Sums in pipe order (deterministic). Sizes *inflow to num_domains.
void ComputeHeadInflow(const FlowNetwork& network, std::vector<double>* inflow);

// The head offset of pipe p, 0 without fluid weight.
inline double PipeHeadOffset(const FlowNetwork& network, std::size_t p) {
  return network.has_head_offsets() ? network.pipe_head_offset()[p] : 0.0;
}

// The flow from b into a through pipe p at the network's pressures, m^2/s.
inline double PipeInflowToA(const FlowNetwork& network, std::size_t p) {
  const auto pressure = network.pressure();
  return network.pipe_conductance()[p] *
         (pressure[network.pipe_domain_b()[p]] - pressure[network.pipe_domain_a()[p]] -
          PipeHeadOffset(network, p));
}

}  // namespace seep::core
