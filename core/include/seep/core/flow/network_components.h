// Connected components of the non-fixed part of a network, and whether each touches a
// fixed-pressure node ("anchored"). A steady state is unique only on anchored components; a closed
// one needs a conservation condition instead (steady_state_solver.h).
#pragma once

#include <cstdint>
#include <vector>

#include "seep/core/flow/flow_network.h"

namespace seep::core {

struct NetworkComponents {
  // Per domain: component index in [0, num_components), or -1 for fixed-pressure domains.
  // Components are numbered in order of their lowest domain index (deterministic).
  std::vector<std::int32_t> component_of_domain;
  std::vector<std::uint8_t> anchored;      // per component: 1 if a pipe joins it to a fixed node
  std::vector<std::int32_t> first_domain;  // per component: its lowest domain index
  std::int32_t num_components = 0;
};

// O(pipes + domains). The network must be valid.
NetworkComponents FindNetworkComponents(const FlowNetwork& network);

}  // namespace seep::core
