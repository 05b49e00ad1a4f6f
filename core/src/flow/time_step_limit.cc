#include "seep/core/flow/time_step_limit.h"

#include <cmath>
#include <string>
#include <vector>

#include "seep/core/flow/storage_volume.h"

namespace seep::core {

Result<CriticalTimeStep> ComputeCriticalTimeStep(const FlowNetwork& network, double bulk_modulus,
                                                 const StorageModel& storage,
                                                 std::span<double> per_domain) {
  CriticalTimeStepScratch scratch;
  return ComputeCriticalTimeStep(network, bulk_modulus, storage, per_domain, &scratch);
}

Result<CriticalTimeStep> ComputeCriticalTimeStep(const FlowNetwork& network, double bulk_modulus,
                                                 const StorageModel& storage,
                                                 std::span<double> per_domain,
                                                 CriticalTimeStepScratch* scratch) {
  if (!(std::isfinite(bulk_modulus) && bulk_modulus > 0.0)) {
    return InvalidArgument("flow.fluid.bulk_modulus: must be finite and > 0 (got " +
                           std::to_string(bulk_modulus) + ")");
  }
  const std::size_t n = network.num_domains();
  if (!per_domain.empty() && per_domain.size() != n) {
    return InvalidArgument("flow.time_step_limit: per_domain has " +
                           std::to_string(per_domain.size()) + " entries, expected " +
                           std::to_string(n));
  }
  SEEP_RETURN_IF_ERROR(ComputeStorageVolumesInto(network, storage, &scratch->storage_volume));
  const std::vector<double>& vs = scratch->storage_volume;
  std::vector<double>& sum_c = scratch->conductance_sum;
  sum_c.assign(n, 0.0);
  const auto a = network.pipe_domain_a();
  const auto b = network.pipe_domain_b();
  const auto c = network.pipe_conductance();
  for (std::size_t p = 0; p < c.size(); ++p) {
    sum_c[a[p]] += c[p];
    sum_c[b[p]] += c[p];
  }

  CriticalTimeStep out;
  const auto role = network.role();
  for (std::size_t d = 0; d < n; ++d) {
    double dt = std::numeric_limits<double>::infinity();
    if (role[d] != DomainRole::kFixedPressure && sum_c[d] > 0.0) {
      dt = vs[d] / (bulk_modulus * sum_c[d]);
    }
    if (!per_domain.empty()) per_domain[d] = dt;
    if (dt < out.dt_crit) {
      out.dt_crit = dt;
      out.limiting_domain = static_cast<std::int32_t>(d);
      out.limiting_storage_volume = vs[d];
      out.limiting_conductance_sum = sum_c[d];
    }
  }
  return out;
}

}  // namespace seep::core
