#include "seep/core/flow/pipe_head.h"

namespace seep::core {

void ComputeHeadInflow(const FlowNetwork& network, std::vector<double>* inflow) {
  inflow->assign(network.num_domains(), 0.0);
  if (!network.has_head_offsets()) return;
  const auto a = network.pipe_domain_a();
  const auto b = network.pipe_domain_b();
  const auto c = network.pipe_conductance();
  const auto offset = network.pipe_head_offset();
  double* out = inflow->data();
  for (std::size_t p = 0; p < c.size(); ++p) {
    const double q = c[p] * offset[p];  // the part of b -> a that the weight holds back
    out[a[p]] -= q;
    out[b[p]] += q;
  }
}

}  // namespace seep::core
