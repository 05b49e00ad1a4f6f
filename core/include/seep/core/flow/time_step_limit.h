// The explicit critical time step (docs/physics.md §4.1, S1), general form of seed eq. 5:
//
//   dt_i = V_s,i / (K_f sum_j C_ij)   for every non-fixed domain i (pipes to fixed nodes count),
//   dt_crit = min_i dt_i.
//
// Below dt_crit the explicit update is a convex combination of old pressures (positivity, discrete
// maximum principle); on bipartite networks (lattices, chains) it is also the stability limit.
// With N identical pipes and L = 2 R it reduces to eq. 5, dt = 24 mu R V/(N K_f a^3).
#pragma once

#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "seep/core/flow/flow_network.h"
#include "seep/core/flow/fluid.h"
#include "seep/core/status.h"

namespace seep::core {

struct CriticalTimeStep {
  double dt_crit = std::numeric_limits<double>::infinity();  // s; inf when nothing limits.
  std::int32_t limiting_domain = -1;      // argmin (lowest index on ties); -1 when nothing limits.
  double limiting_storage_volume = 0.0;   // V_s of that domain, m^2.
  double limiting_conductance_sum = 0.0;  // sum_j C_ij of that domain, m^2/(Pa s).
};

// Fills dt_i per domain (inf for fixed-pressure domains and domains without pipes) and returns the
// minimum. `per_domain` may be empty when only the minimum is wanted.
Result<CriticalTimeStep> ComputeCriticalTimeStep(const FlowNetwork& network, double bulk_modulus,
                                                 const StorageModel& storage,
                                                 std::span<double> per_domain = {});

// What ComputeCriticalTimeStep works in, kept by a caller that calls it at every step so that it
// allocates nothing once sized.
struct CriticalTimeStepScratch {
  std::vector<double> storage_volume, conductance_sum;
};
Result<CriticalTimeStep> ComputeCriticalTimeStep(const FlowNetwork& network, double bulk_modulus,
                                                 const StorageModel& storage,
                                                 std::span<double> per_domain,
                                                 CriticalTimeStepScratch* scratch);

}  // namespace seep::core
