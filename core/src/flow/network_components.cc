#include "seep/core/flow/network_components.h"

#include <utility>

namespace seep::core {

namespace {
std::int32_t Root(std::vector<std::int32_t>& parent, std::int32_t x) {
  while (parent[x] != x) {
    parent[x] = parent[parent[x]];  // path halving
    x = parent[x];
  }
  return x;
}
}  // namespace

NetworkComponents FindNetworkComponents(const FlowNetwork& network) {
  const std::size_t nd = network.num_domains();
  const auto role = network.role();
  const auto pa = network.pipe_domain_a();
  const auto pb = network.pipe_domain_b();
  std::vector<std::int32_t> parent(nd);
  for (std::size_t d = 0; d < nd; ++d) parent[d] = static_cast<std::int32_t>(d);
  auto is_fixed = [&](std::int32_t d) { return role[d] == DomainRole::kFixedPressure; };

  for (std::size_t p = 0; p < pa.size(); ++p) {
    if (is_fixed(pa[p]) || is_fixed(pb[p])) continue;
    std::int32_t ra = Root(parent, pa[p]);
    std::int32_t rb = Root(parent, pb[p]);
    if (ra == rb) continue;
    if (rb < ra) std::swap(ra, rb);
    parent[rb] = ra;  // the lowest index is the root: labels do not depend on pipe order
  }

  NetworkComponents out;
  out.component_of_domain.assign(nd, -1);
  for (std::size_t d = 0; d < nd; ++d) {
    if (is_fixed(static_cast<std::int32_t>(d))) continue;
    const std::int32_t r = Root(parent, static_cast<std::int32_t>(d));
    if (r == static_cast<std::int32_t>(d)) {
      out.component_of_domain[d] = out.num_components++;
      out.first_domain.push_back(r);
    } else {
      out.component_of_domain[d] = out.component_of_domain[r];  // r < d: already labelled
    }
  }
  out.anchored.assign(static_cast<std::size_t>(out.num_components), 0);
  for (std::size_t p = 0; p < pa.size(); ++p) {
    const bool fa = is_fixed(pa[p]);
    const bool fb = is_fixed(pb[p]);
    if (fa == fb) continue;
    out.anchored[out.component_of_domain[fa ? pb[p] : pa[p]]] = 1;
  }
  return out;
}

}  // namespace seep::core
