#include "seep/core/network/boundary_regions.h"

#include <fmt/format.h>

namespace seep::core {

void AssignBoundaryRegions(const SceneSpec& scene, const DomainNetwork& domains,
                           FlowNetworkData* data, std::vector<RegionNodes>* regions) {
  const std::vector<BoundaryRegionSpec>& specs = scene.boundary.regions;
  regions->assign(specs.size(), RegionNodes{});
  if (specs.empty()) return;
  for (std::size_t d = 0; d < domains.num_domains(); ++d) {
    const bool free = data->role[d] == DomainRole::kFree;
    bool taken = false;
    for (std::size_t r = 0; r < specs.size(); ++r) {
      if (!RegionContains(specs[r].shape, domains.centroid_x[d], domains.centroid_y[d])) continue;
      RegionNodes& region = (*regions)[r];
      ++region.centroids_inside;
      if (!free || taken) continue;
      taken = true;
      region.nodes.push_back(static_cast<std::int32_t>(d));
      region.apparent_volume_m2 += domains.apparent_volume[d];
      const bool pressure = std::holds_alternative<FixedPressure>(specs[r].condition);
      data->role[d] = pressure ? DomainRole::kFixedPressure : DomainRole::kSource;
    }
  }
}

Status SetRegionConditions(const SceneSpec& scene, SceneNetwork* net) {
  const std::vector<BoundaryRegionSpec>& specs = scene.boundary.regions;
  FlowNetwork& flow = net->flow;
  const std::span<const double> volume = net->domains.apparent_volume;
  for (std::size_t r = 0; r < specs.size() && r < net->regions.size(); ++r) {
    const RegionNodes& region = net->regions[r];
    if (const auto* fixed = std::get_if<FixedPressure>(&specs[r].condition)) {
      auto pressure = flow.mutable_pressure();
      for (const std::int32_t d : region.nodes)
        pressure[static_cast<std::size_t>(d)] = fixed->pressure_pa;
      continue;
    }
    const double rate = std::get<FixedFlux>(specs[r].condition).rate_m2_s;
    // V_d / sum V_d; an equal share should every V_d be 0 (a degenerate detection).
    const bool by_volume = region.apparent_volume_m2 > 0.0;
    const double count = static_cast<double>(region.nodes.size());
    for (const std::int32_t d : region.nodes) {
      const double share =
          by_volume ? volume[static_cast<std::size_t>(d)] / region.apparent_volume_m2 : 1.0 / count;
      SEEP_RETURN_IF_ERROR(flow.SetSource(d, rate * share));
    }
  }
  return Status::Ok();
}

Status CheckRegionsHoldDomains(const SceneSpec& scene, const SceneNetwork& net) {
  const std::vector<BoundaryRegionSpec>& specs = scene.boundary.regions;
  for (std::size_t r = 0; r < specs.size() && r < net.regions.size(); ++r) {
    const RegionNodes& region = net.regions[r];
    if (!region.nodes.empty()) continue;
    const std::string at = fmt::format("scene.boundary.regions[{}] ('{}')", r, specs[r].name);
    if (region.centroids_inside == 0) {
      return FailedPrecondition(fmt::format(
          "{}: contains no domain centroid (the network has {} domains; enlarge or move the "
          "{})",
          at, net.domains.num_domains(), RegionShapeName(specs[r].shape)));
    }
    return FailedPrecondition(fmt::format(
        "{}: its {} domain centroids belong to the boundary already (the well, or an earlier "
        "region), so it holds none",
        at, region.centroids_inside));
  }
  return Status::Ok();
}

}  // namespace seep::core
